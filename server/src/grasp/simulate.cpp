#include "grasp/simulate.h"

#include "grasp/hand_collision.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace graspsim::grasp {
namespace {

// A sweep casts every kPassStride-th ray of a link first (see Sweep).
constexpr size_t kPassStride = 8;
// Added to every ray's length: the float tfar then never rounds below a hit the double comparison keeps, m.
constexpr double kReachMargin = 1e-6;
// The material of everything not given one.
const std::string kDefaultMaterial = "default";
// Rays shorter than this are culled by a division-free test (NearBoxAndBall), m.
constexpr double kShortReach = 0.01;

// A direction prepared for slab tests: its reciprocals, and which components are zero.
struct SlabDirection {
  explicit SlabDirection(const Vec3& d) {
    for (int k = 0; k < 3; ++k) {
      parallel[k] = std::abs(d[k]) < 1e-15;
      inverse[k] = parallel[k] ? 0.0 : 1.0 / d[k];
    }
  }
  Vec3 inverse;
  bool parallel[3];
};

// Does the segment p + t d, t in [0, length], meet the box [lo, hi]? (slab test)
bool SegmentMeetsBox(const Vec3& p, const SlabDirection& d, double length, const Vec3& lo, const Vec3& hi) {
  double t0 = 0, t1 = length;
  for (int k = 0; k < 3; ++k) {
    if (d.parallel[k]) {
      if (p[k] < lo[k] || p[k] > hi[k]) return false;
      continue;
    }
    double a = (lo[k] - p[k]) * d.inverse[k], b = (hi[k] - p[k]) * d.inverse[k];
    if (a > b) std::swap(a, b);
    t0 = std::max(t0, a);
    t1 = std::min(t1, b);
    if (t0 > t1) return false;
  }
  return true;
}

// Can a segment of length `reach` from p meet the box [lo, hi] or the ball (centre, radius)? A division-free
// test, conservative whatever the direction: tight for the short rays of a sweep's second pass.
bool NearBoxAndBall(const Vec3& p, double reach, const Vec3& lo, const Vec3& hi, const Vec3& centre, double radius) {
  if ((p.array() < lo.array() - reach).any() || (p.array() > hi.array() + reach).any()) return false;
  return (p - centre).squaredNorm() <= (radius + reach) * (radius + reach);
}

// Does the segment p + t u, t in [0, length] (u unit), come within `radius` of `centre`?
bool SegmentMeetsBall(const Vec3& p, const Vec3& u, double length, const Vec3& centre, double radius) {
  const double t = std::clamp((centre - p).dot(u), 0.0, length);
  return (p + t * u - centre).squaredNorm() <= radius * radius;
}

// Does the ball (centre, radius) meet the box [lo, hi]?
bool BallMeetsBox(const Vec3& centre, double radius, const Vec3& lo, const Vec3& hi) {
  const Vec3 nearest = centre.cwiseMax(lo).cwiseMin(hi);
  return (nearest - centre).squaredNorm() <= radius * radius;
}

}  // namespace

GraspSimulator::GraspSimulator(const HandModel& hand, const GraspObject& object, const ClosingParams& params)
    : hand_(hand), object_(object), params_(params), link_moves_(hand.links().size(), false),
      self_collision_(hand, -params.contact_tolerance) {
  std::vector<Pose> poses(hand.links().size());
  for (size_t p = 0; p < hand.preshape_names().size(); ++p) {
    hand.LinkPoses(Pose(), hand.PreshapeJoints(p), &poses);
    double reach = 0;
    for (size_t l = 0; l < poses.size(); ++l) reach = std::max(reach, poses[l].position.norm() + hand.links()[l].reach);
    preshape_reach_.push_back(reach);
  }
  for (const HandFinger& finger : hand.fingers()) {
    for (int l : finger.links) link_moves_[l] = true;
  }
  for (size_t l = 0; l < hand.links().size(); ++l) {
    all_links_.push_back(static_cast<int>(l));
    const auto it = params.link_materials.find(hand.links()[l].name);
    const std::string& material = it == params.link_materials.end() ? "" : it->second;
    link_friction_.push_back(PairFriction(params, material, params.object_material));
  }
}

double PairFriction(const ClosingParams& params, const std::string& a, const std::string& b) {
  const std::string& x = a.empty() ? kDefaultMaterial : a;
  const std::string& y = b.empty() ? kDefaultMaterial : b;
  for (const FrictionPair& pair : params.friction_pairs) {
    const std::string& p = pair.material_a.empty() ? kDefaultMaterial : pair.material_a;
    const std::string& q = pair.material_b.empty() ? kDefaultMaterial : pair.material_b;
    if ((p == x && q == y) || (p == y && q == x)) return pair.friction;
  }
  return params.friction;
}

Quat GraspSimulator::HandOrientation(const Candidate& c) {
  const Vec3 z = c.approach;
  const Vec3 x0 = (c.reference - c.reference.dot(z) * z).normalized();
  const Vec3 x = Eigen::AngleAxisd(c.roll, z) * x0;
  Mat3 r;
  r.col(0) = x;
  r.col(1) = z.cross(x);
  r.col(2) = z;
  return Quat(r).normalized();
}

double GraspSimulator::Sweep(const std::vector<int>& links, SimulationWork* w) const {
  const double tol = params_.contact_tolerance;
  const Vec3 lo = object_.lo() - Vec3::Constant(tol), hi = object_.hi() + Vec3::Constant(tol);
  const Vec3 centre = object_.centroid();
  const double ball = object_.characteristic_length() + tol;  // every vertex lies within it
  double best = 1.0;
  bool any = false;
  auto record = [&](double t, double length, const Vec3& point, const Vec3& normal, int link) {
    w->raw.push_back({point, normal, link});
    w->raw_t.push_back(t);
    w->raw_length.push_back(length);
    best = std::min(best, t / length);
    any = true;
  };

  // Hand samples against the object: only samples whose face leads the motion can strike first. Links go
  // front first (the fingertips before the palm on an approach), one batch each, and every later ray is cut at
  // the first contact found so far: a palm behind touching fingertips then casts almost nothing.
  w->link_order.clear();
  for (int l : links) {
    if (!hand_.links()[l].bvh) continue;
    const Pose& a = w->poses[l];
    const Vec3 motion = w->next_poses[l].position - a.position;
    w->link_order.push_back({-(motion.dot(a.position) + hand_.links()[l].reach * motion.norm()), l});
  }
  std::sort(w->link_order.begin(), w->link_order.end());
  for (const auto& [lead, l] : w->link_order) {
    const HandLink& link = hand_.links()[l];
    const Pose& a = w->poses[l];
    const Pose& b = w->next_poses[l];
    const double moved = (b.position - a.position).norm() + link.reach * a.orientation.angularDistance(b.orientation);
    if (!BallMeetsBox(a.position, link.reach + best * moved + tol, lo, hi)) continue;  // nowhere near the object
    const Mat3 ra = a.orientation.toRotationMatrix();
    w->pending.clear();
    if (a.orientation.coeffs() == b.orientation.coeffs()) {
      // A pure translation (an approach, a prismatic jaw): one direction for every sample, so the leading test
      // is a dot product in the link frame and trailing samples cost nothing more.
      const Vec3 d = b.position - a.position;
      const double length = d.norm();
      if (length < 1e-12) continue;
      const Vec3 u = d / length, local = ra.transpose() * u;
      for (const SampleRun& run : link.runs) {
        if (run.normal.dot(local) <= 0) continue;
        for (uint32_t i = run.begin; i < run.end; ++i) w->pending.push_back({a.position + ra * link.samples[i], u, length, i});
      }
    } else {
      // A turning link: the chord of sample s is R_a (Δ s − s) with Δ = T_a⁻¹ T_b, the step as seen from the
      // link, so the leading test needs one product per sample and the world position only the leading ones.
      const Pose delta = a.Inverse() * b;
      const Mat3 rd = delta.orientation.toRotationMatrix();
      // A whole run is skipped when its ball shows that no sample of it leads (the chord (R_Δ − I) s + t_Δ is
      // affine in s, so n·chord varies by at most |(R_Δ − I)ᵀ n| r over the ball) or can come near the object.
      const Mat3 turn = rd - Mat3::Identity();
      const double stretch = turn.norm();  // Frobenius: bounds how much chords differ within a ball
      for (const SampleRun& run : link.runs) {
        const Vec3 chord_centre = turn * run.centre + delta.position;
        if (run.normal.dot(chord_centre) + (turn.transpose() * run.normal).norm() * run.radius <= 0) continue;
        const double longest = chord_centre.norm() + stretch * run.radius;
        if (!NearBoxAndBall(a.position + ra * run.centre, run.radius + best * longest + tol, lo, hi, centre, ball)) {
          continue;
        }
        for (uint32_t i = run.begin; i < run.end; ++i) {
          const Vec3& s_local = link.samples[i];
          const Vec3 chord_local = rd * s_local + delta.position - s_local;
          if (link.normals[i].dot(chord_local) <= 0) continue;
          const double length = chord_local.norm();
          if (length < 1e-12) continue;
          const double reach = best * length + tol;
          const Vec3 p0 = a.position + ra * s_local;
          // Steps are a few millimetres: the division-free test culls nearly as well here.
          if (!NearBoxAndBall(p0, reach, lo, hi, centre, ball)) continue;
          w->pending.push_back({p0, ra * (chord_local / length), length, i});
        }
      }
    }
    // Two passes: every kPassStride-th ray first, which finds the first contact to within a few samples; the
    // rest are then cut there (plus the tolerance), so most of them stop short of the object or are not cast at
    // all. Only hits within the tolerance of the final first contact are ever kept (KeepContacts), and every ray
    // still reaches that far, so the kept contacts are those of one pass; they are put back in sample order.
    w->link_hits.clear();
    for (int pass = 0; pass < 2; ++pass) {
      w->rays.Clear();
      w->ray_length.clear();
      for (size_t k = 0; k < w->pending.size(); ++k) {
        if ((k % kPassStride == 0) != (pass == 0)) continue;
        const SimulationWork::PendingRay& r = w->pending[k];
        const double reach = best * r.length + tol + kReachMargin;
        // Long rays (the first link of an approach) by the box and the bounding ball, which cull different
        // shapes (a long object, a round one); short ones by the cheaper test.
        if (reach < kShortReach ? !NearBoxAndBall(r.origin, reach, lo, hi, centre, ball)
                                : !SegmentMeetsBall(r.origin, r.direction, reach, centre, ball) ||
                                      !SegmentMeetsBox(r.origin, SlabDirection(r.direction), reach, lo, hi)) {
          continue;
        }
        w->rays.Add(r.origin, r.direction, reach, r.sample);
        w->ray_length.push_back(static_cast<float>(r.length));
      }
      object_.bvh().Intersect(&w->rays);
      for (size_t r = 0; r < w->rays.size(); ++r) {
        if (!w->rays.Hit(r)) continue;
        const double t = w->rays.T(r);
        const Vec3 point = w->rays.Origin(r) + t * w->rays.Direction(r);
        const Vec3 normal = -object_.face_normals()[w->rays.Triangle(r)];
        w->link_hits.push_back({w->rays.Id(r), t, w->ray_length[r], point, normal});
        best = std::min(best, t / w->ray_length[r]);
      }
    }
    std::sort(w->link_hits.begin(), w->link_hits.end(),
              [](const auto& x, const auto& y) { return x.sample < y.sample; });
    for (const auto& h : w->link_hits) record(h.t, h.length, h.point, h.normal, l);
  }

  // Sharp object vertices against each link, in the link frame: the relative motion runs backwards.
  for (int l : links) {
    const HandLink& link = hand_.links()[l];
    if (!link.bvh || object_.sharp_vertices().empty()) continue;
    const Pose& a = w->poses[l];
    const Pose& b = w->next_poses[l];
    const double moved = (b.position - a.position).norm() + link.reach * a.orientation.angularDistance(b.orientation);
    const double radius = link.reach + best * link.reach * a.orientation.angularDistance(b.orientation) + tol;
    if (!BallMeetsBox(a.position, radius + moved, lo, hi)) continue;
    const Pose ia = a.Inverse(), ib = b.Inverse();
    const Mat3 ra = a.orientation.toRotationMatrix();
    w->rays.Clear();
    w->ray_length.clear();
    // A vertex can reach the link only if it lies within the link's reach of the path of the link's origin, up
    // to the first contact found so far.
    const Vec3 path = best * (b.position - a.position);
    const double path2 = path.squaredNorm();
    // The distance to the path is 1-Lipschitz: a cluster farther than radius + its own radius holds no vertex
    // nearer than radius. The vertices that pass go in their original order, as every ray of a sweep does.
    auto path_distance2 = [&](const Vec3& v) {
      const double along = path2 > 0 ? std::clamp((v - a.position).dot(path) / path2, 0.0, 1.0) : 0.0;
      return (v - a.position - along * path).squaredNorm();
    };
    w->vertex_ids.clear();
    for (const GraspObject::VertexCluster& cluster : object_.sharp_clusters()) {
      const double r = radius + cluster.radius;
      if (path_distance2(cluster.centre) > r * r) continue;
      for (uint32_t i : cluster.members) {
        if (path_distance2(object_.sharp_vertices()[i]) <= radius * radius) w->vertex_ids.push_back(i);
      }
    }
    std::sort(w->vertex_ids.begin(), w->vertex_ids.end());
    for (uint32_t i : w->vertex_ids) {
      const Vec3& v = object_.sharp_vertices()[i];
      const Vec3 v0 = ia * v;
      const Vec3 d = ib * v - v0;
      const double length = d.norm();
      if (length < 1e-12) continue;
      w->rays.Add(v0, d / length, best * length + tol, 0);
      w->ray_length.push_back(static_cast<float>(length));
    }
    link.bvh->Intersect(&w->rays);
    for (size_t r = 0; r < w->rays.size(); ++r) {
      if (!w->rays.Hit(r)) continue;
      // The contact is the object's vertex (the ray's origin in the world); the push is the link face's normal.
      const Vec3 vertex = a * w->rays.Origin(r);
      record(w->rays.T(r), w->ray_length[r], vertex, ra * link.face_normals[w->rays.Triangle(r)], l);

    }
  }
  return any ? std::max(0.0, best) : 1.0;
}

void GraspSimulator::KeepContacts(double fraction, double extra_gap, bool palm_only, SimulationWork* w) const {
  for (size_t i = 0; i < w->raw.size(); ++i) {
    if (palm_only && link_moves_[w->raw[i].link]) continue;
    const double gap = w->raw_t[i] - fraction * w->raw_length[i] + extra_gap;
    if (gap <= params_.contact_tolerance) w->contacts.push_back(w->raw[i]);
  }
  w->raw.clear();
  w->raw_t.clear();
  w->raw_length.clear();
}

bool GraspSimulator::CollidesWithObstacles(const std::vector<Pose>& poses) const {
  // Touching is allowed (a fingertip resting on the table); overlapping by more than the tolerance is not.
  const double margin = -params_.contact_tolerance;
  for (size_t l = 0; l < poses.size(); ++l) {
    const Mat3 r = poses[l].orientation.toRotationMatrix();
    for (const LinkBox& box : hand_.links()[l].boxes) {
      const LinkBox placed{poses[l] * box.centre, r * box.axes, box.half};
      for (const ObstacleBox& obstacle : object_.obstacles()) {
        if (BoxesOverlap(placed, obstacle, margin)) return true;
      }
    }
  }
  return false;
}

void GraspSimulator::CloseFinger(size_t f, const Pose& base, SimulationWork* w) const {
  const HandFinger& finger = hand_.fingers()[f];
  const double range = hand_.ClosingRange(f, w->q);
  std::vector<double>& q = w->q;
  double s = 0;
  while (s < range) {
    const double s1 = finger.straight ? range : std::min(range, s + finger.max_step);
    for (const auto& [j, rate] : finger.joint_rates) q[j] += rate * (s1 - s);
    hand_.LinkPoses(base, q, &w->next_poses);
    const double fraction = Sweep(finger.links, w);
    if (fraction < 1.0) {
      // Stop where the first link touched: undo the rest of the step.
      for (const auto& [j, rate] : finger.joint_rates) q[j] -= rate * (1 - fraction) * (s1 - s);
      KeepContacts(fraction, 0, false, w);
      hand_.LinkPoses(base, q, &w->poses);
      return;
    }
    // Hits just beyond the step's end touch only if the finger stops there, at its joint limit.
    KeepContacts(1.0, s1 < range ? std::numeric_limits<double>::infinity() : 0.0, false, w);
    std::swap(w->poses, w->next_poses);
    s = s1;
  }
}

void GraspSimulator::ReduceContacts(SimulationWork* w) const {
  // Per link, the patch's extreme points along two directions across its mean normal: the wrench hull of a
  // flat patch is that of its corners, so the rest add nothing but qhull time.
  std::vector<GraspContact>& all = w->contacts;
  std::stable_sort(all.begin(), all.end(), [](const auto& a, const auto& b) { return a.link < b.link; });
  size_t out = 0;
  for (size_t begin = 0; begin < all.size();) {
    size_t end = begin;
    Vec3 mean = Vec3::Zero();
    while (end < all.size() && all[end].link == all[begin].link) mean += all[end++].normal;
    if (end - begin <= static_cast<size_t>(params_.contacts_per_link)) {
      for (size_t i = begin; i < end; ++i) all[out++] = all[i];
      begin = end;
      continue;
    }
    const Vec3 n = mean.norm() > 0 ? Vec3(mean.normalized()) : Vec3::UnitZ();
    const Vec3 u = n.unitOrthogonal(), v = n.cross(u);
    // Extreme along `first`, ties (a patch edge lying across it, as on a box whose faces line up with u and v)
    // broken along `second`: each of the four picks is then a different corner of a rectangle in any
    // orientation (plain extremes kept only 3 of its 4 corners when lined up: ε 15 % low, test_grasp_contacts).
    constexpr double kTie = 1e-9;  // m
    auto beyond = [&](size_t i, size_t current, const Vec3& first, const Vec3& second) {
      const Vec3 d = all[i].point - all[current].point;
      const double along = d.dot(first);
      return along > kTie || (along >= -kTie && d.dot(second) > kTie);
    };
    size_t pick[4] = {begin, begin, begin, begin};
    for (size_t i = begin; i < end; ++i) {
      if (beyond(i, pick[0], u, v)) pick[0] = i;
      if (beyond(i, pick[1], -u, -v)) pick[1] = i;
      if (beyond(i, pick[2], v, -u)) pick[2] = i;
      if (beyond(i, pick[3], -v, u)) pick[3] = i;
    }
    std::sort(pick, pick + 4);
    GraspContact kept[4];
    size_t count = 0;
    for (int k = 0; k < 4 && static_cast<int>(count) < params_.contacts_per_link; ++k) {
      if (k == 0 || pick[k] != pick[k - 1]) kept[count++] = all[pick[k]];
    }
    for (size_t k = 0; k < count; ++k) all[out++] = kept[k];
    begin = end;
  }
  all.resize(out);
}

Outcome GraspSimulator::Simulate(const Candidate& c, SimulationWork* w) const {
  const size_t links = hand_.links().size();
  w->poses.resize(links);
  w->next_poses.resize(links);
  w->contacts.clear();
  w->raw.clear();
  w->raw_t.clear();
  w->raw_length.clear();
  w->quality = Quality();
  w->q = hand_.PreshapeJoints(c.preshape);

  // 1-2. From far back along the approach line, one straight sweep of the open hand through the object.
  const Vec3 z = c.approach;
  const double back = (c.target - object_.centroid()).norm() + object_.characteristic_length() +
                      preshape_reach_[c.preshape] + 0.01;
  const double travel = 2 * back;
  const Pose start{c.target - back * z, HandOrientation(c)};
  hand_.LinkPoses(start, w->q, &w->poses);
  for (size_t l = 0; l < links; ++l) w->next_poses[l] = {w->poses[l].position + travel * z, w->poses[l].orientation};
  const double fraction = Sweep(all_links_, w);
  if (w->raw.empty()) return Outcome::kMissed;

  // 3. Back off; the palm (links no finger moves) keeps its contacts when the standoff is within the tolerance.
  const double advance = fraction * travel - c.standoff;
  w->hand_pose = {start.position + advance * z, start.orientation};
  KeepContacts(fraction, c.standoff, true, w);
  hand_.LinkPoses(w->hand_pose, w->q, &w->poses);
  if (CollidesWithObstacles(w->poses)) return Outcome::kCollision;
  // The way there: the open hand swept back to where the sweep started (the object itself cannot be in the
  // way: the sweep stopped at the first contact with it).
  if (HandOverlapsObstacles(hand_, w->poses, -advance * z, object_.obstacles(), -params_.contact_tolerance)) {
    return Outcome::kCollision;
  }

  // 4. Close the fingers one after the other; each stops at its own first contact.
  for (size_t f = 0; f < hand_.fingers().size(); ++f) CloseFinger(f, w->hand_pose, w);
  if (CollidesWithObstacles(w->poses) || self_collision_.Collides(w->poses)) return Outcome::kCollision;
  w->joints = w->q;

  // 5. Score.
  ReduceContacts(w);
  w->quality = GraspQuality(w->contacts.data(), w->contacts.size(), object_.centroid(),
                            object_.characteristic_length(), link_friction_, params_.cone_edges, &w->wrenches);
  return Outcome::kGrasp;
}

}  // namespace graspsim::grasp
