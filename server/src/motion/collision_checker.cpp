#include "motion/collision_checker.h"

#include <algorithm>
#include <cmath>

#include "core/error.h"
#include "motion/short_number.h"

namespace graspsim::motion {
namespace {

bool BallTouchesBox(const Vec3& c, double r, const Obstacles::Box& box) {
  const Vec3 local = box.rotation.transpose() * (c - box.centre);
  const Vec3 outside = (local.cwiseAbs() - box.half).cwiseMax(0.0);
  return outside.squaredNorm() < r * r;
}

bool BallTouchesCylinder(const Vec3& c, double r, const Obstacles::Cylinder& cylinder) {
  const Vec3 local = cylinder.rotation.transpose() * (c - cylinder.centre);
  const double dr = std::max(std::hypot(local.x(), local.y()) - cylinder.radius, 0.0);
  const double dz = std::max(std::abs(local.z()) - cylinder.half_length, 0.0);
  return dr * dr + dz * dz < r * r;
}

}  // namespace

Obstacles CollectObstacles(const SceneModel& model, const SceneState& state, const std::string& robot_id,
                           const std::vector<std::string>& ignore, double grid_cell) {
  Obstacles out;
  for (size_t b = 0; b < model.bodies.size(); ++b) {
    const BodySpec& body = model.bodies[b];
    if (!robot_id.empty() && body.robot_id == robot_id) continue;
    const auto ignored = [&](const std::string& id) {
      return !id.empty() && std::find(ignore.begin(), ignore.end(), id) != ignore.end();
    };
    if (ignored(body.id) || ignored(body.robot_id) || body.collision.empty()) continue;
    const uint32_t index = static_cast<uint32_t>(out.body_ids.size());
    out.body_ids.push_back(body.id);
    for (const Geometry& geometry : body.collision) {
      const Rigid pose = Rigid::From(state.body_poses[b] * geometry.origin);
      switch (geometry.kind) {
        case Geometry::Kind::kBox:
          out.boxes.push_back({pose.rotation, pose.translation, 0.5 * geometry.box_size, index});
          break;
        case Geometry::Kind::kSphere:
          out.balls.push_back({pose.translation, geometry.radius, index});
          break;
        case Geometry::Kind::kCylinder:
          out.cylinders.push_back({pose.rotation, pose.translation, geometry.radius, 0.5 * geometry.length, index});
          break;
        case Geometry::Kind::kMesh:
          if (!geometry.mesh || geometry.mesh->triangles.empty()) break;
          out.grids.push_back({std::make_shared<DistanceGrid>(geometry.mesh, grid_cell, 0.05), pose.Inverse(), index});
          break;
      }
    }
  }
  return out;
}

namespace {

void StoreRotation(const Mat3& r, float* out) {
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) out[3 * i + j] = static_cast<float>(r(i, j));
  }
}

void StoreVector(const Vec3& v, float* out) {
  for (int i = 0; i < 3; ++i) out[i] = static_cast<float>(v[i]);
}

// A link's offset for the kernel; a rotation that is a signed permutation to 1e-9 is stored exactly, as one.
void StoreOffset(const Rigid& offset, kernel::Link* link) {
  Mat3 r = offset.rotation;
  int permutation[3];
  bool permuted = true;
  for (int j = 0; j < 3 && permuted; ++j) {
    Eigen::Index k;
    r.col(j).cwiseAbs().maxCoeff(&k);
    permutation[j] = static_cast<int>(k);
    const Vec3 unit = Vec3::Unit(k) * (r(k, j) < 0 ? -1.0 : 1.0);
    permuted = (r.col(j) - unit).cwiseAbs().maxCoeff() < 1e-9;
    if (permuted) r.col(j) = unit;
  }
  if (permuted) {
    for (int j = 0; j < 3; ++j) link->permutation[j] = permutation[j];
    StoreRotation(r, link->rotation);
  } else {
    StoreRotation(offset.rotation, link->rotation);
  }
  StoreVector(offset.translation, link->translation);
}

// Appends `indices` to *out in bit-reversed order of their rank (0, n/2, n/4, 3n/4, ...), so that any prefix
// samples them evenly.
void AppendSpreadOut(const std::vector<uint32_t>& indices, std::vector<uint32_t>* out) {
  const size_t n = indices.size();
  int bits = 0;
  while ((size_t{1} << bits) < n) ++bits;
  for (size_t rank = 0; rank < (size_t{1} << bits); ++rank) {
    size_t reversed = 0;
    for (int b = 0; b < bits; ++b) reversed |= ((rank >> b) & 1u) << (bits - 1 - b);
    if (reversed < n) out->push_back(indices[reversed]);
  }
}

}  // namespace

CollisionChecker::CollisionChecker(const ArmModel& arm, ArmSphereModel spheres, Obstacles obstacles, double resolution)
    : arm_(arm), spheres_(std::move(spheres)), obstacles_(std::move(obstacles)), resolution_(resolution) {
  const std::vector<ArmLink>& links = arm_.links();
  // The kernel turns revolute joints about z only: each revolute link's frame is rotated by A (A z = its axis),
  // so its offset becomes A_parent^T O A, its spheres A^T c, its children's offsets A^T O_child.
  // Rigid links are folded into their parent's frame (their offset composed into their spheres and their
  // children's offsets, their own made the identity), so FK copies a transform for them instead of multiplying.
  std::vector<Mat3> to_kernel_frame(links.size(), Mat3::Identity());
  std::vector<Rigid> folded(links.size());  // kernel frame of the link FK places -> the link's kernel frame
  sphere_begin_.push_back(0);
  for (size_t l = 0; l < links.size(); ++l) {
    const LinkSpheres& link_spheres = spheres_.links[l];
    kernel::Link link;
    link.parent = links[l].parent;
    link.dof = links[l].dof;
    link.kind = links[l].dof < 0 ? kernel::kRigid
                                 : (links[l].type == JointType::kPrismatic ? kernel::kPrismatic : kernel::kRevolute);
    if (link.kind == kernel::kRevolute) {
      const Vec3 z = links[l].axis.normalized(), x = z.unitOrthogonal();
      to_kernel_frame[l].col(0) = x;
      to_kernel_frame[l].col(1) = z.cross(x);
      to_kernel_frame[l].col(2) = z;
    }
    const Mat3& frame = to_kernel_frame[l];
    const Mat3 parent_frame = link.parent >= 0 ? to_kernel_frame[link.parent] : Mat3::Identity();
    Rigid offset{parent_frame.transpose() * links[l].offset.rotation * frame,
                 parent_frame.transpose() * links[l].offset.translation};
    if (link.parent >= 0) offset = folded[link.parent] * offset;
    if (link.kind == kernel::kRigid && link.parent >= 0) {
      folded[l] = offset;
      offset = Rigid();
      link.same_frame_as_parent = 1;
    }
    StoreOffset(offset, &link);
    StoreVector(links[l].axis.normalized(), link.axis);  // prismatic: its frame is not rotated
    link.sphere_begin = static_cast<int32_t>(sphere_x_.size());
    for (size_t s = 0; s < link_spheres.centres.size(); ++s) {
      const Vec3 c = folded[l] * (frame.transpose() * link_spheres.centres[s]);
      sphere_x_.push_back(static_cast<float>(c.x()));
      sphere_y_.push_back(static_cast<float>(c.y()));
      sphere_z_.push_back(static_cast<float>(c.z()));
      sphere_radius_.push_back(static_cast<float>(link_spheres.radii[s]) + kernel::kFloatMargin);
      radii_.push_back(link_spheres.radii[s] + kernel::kFloatMargin);
    }
    link.sphere_end = static_cast<int32_t>(sphere_x_.size());
    sphere_begin_.push_back(static_cast<uint32_t>(radii_.size()));
    StoreVector(folded[l] * (frame.transpose() * link_spheres.bound_centre), link.bound_centre);
    link.bound_radius = link_spheres.bound_radius < 0 ? -1.0f
                                                      : static_cast<float>(link_spheres.bound_radius) + 2 * kernel::kFloatMargin;
    // Links rigid on the base never move: where they meet the scene (the base standing on the table) no plan
    // can change it, so the arm's mounting is not a collision.
    link.against_obstacles = spheres_.group[l] >= 0 ? 1 : 0;
    kernel_links_.push_back(link);
  }
  for (const auto& box : obstacles_.boxes) {
    kernel::Box k;
    StoreRotation(box.rotation.transpose(), k.rotation_t);
    StoreVector(box.centre, k.centre);
    StoreVector(box.half, k.half);
    k.bound_radius = static_cast<float>(box.half.norm()) * 1.0001f;
    kernel_boxes_.push_back(k);
  }
  for (const auto& ball : obstacles_.balls) {
    kernel::Ball k;
    StoreVector(ball.centre, k.centre);
    k.radius = static_cast<float>(ball.radius);
    kernel_balls_.push_back(k);
  }
  for (const auto& cylinder : obstacles_.cylinders) {
    kernel::Cylinder k;
    StoreRotation(cylinder.rotation.transpose(), k.rotation_t);
    StoreVector(cylinder.centre, k.centre);
    k.radius = static_cast<float>(cylinder.radius);
    k.half_length = static_cast<float>(cylinder.half_length);
    k.bound_radius = static_cast<float>(std::hypot(cylinder.radius, cylinder.half_length)) * 1.0001f;
    kernel_cylinders_.push_back(k);
  }
  for (const auto& [a, b] : spheres_.self_pairs) {
    kernel_self_pairs_.push_back(static_cast<int32_t>(a));
    kernel_self_pairs_.push_back(static_cast<int32_t>(b));
  }
  kernel_.links = kernel_links_.data();
  kernel_.link_count = static_cast<int32_t>(kernel_links_.size());
  StoreRotation(arm_.base().rotation, kernel_.base_rotation);
  StoreVector(arm_.base().translation, kernel_.base_translation);
  kernel_.sphere_x = sphere_x_.data();
  kernel_.sphere_y = sphere_y_.data();
  kernel_.sphere_z = sphere_z_.data();
  kernel_.sphere_radius = sphere_radius_.data();
  kernel_.sphere_count = static_cast<int32_t>(sphere_x_.size());
  kernel_.boxes = kernel_boxes_.data();
  kernel_.box_count = static_cast<int32_t>(kernel_boxes_.size());
  kernel_.balls = kernel_balls_.data();
  kernel_.ball_count = static_cast<int32_t>(kernel_balls_.size());
  kernel_.cylinders = kernel_cylinders_.data();
  kernel_.cylinder_count = static_cast<int32_t>(kernel_cylinders_.size());
  kernel_.self_pairs = kernel_self_pairs_.data();
  kernel_.self_pair_count = static_cast<int32_t>(spheres_.self_pairs.size());
  link_inflation_.assign(links.size(), 1.0f);
  pair_inflation_.assign(spheres_.self_pairs.size(), 2.0f);
  kernel_.link_inflation = link_inflation_.data();
  kernel_.pair_inflation = pair_inflation_.data();
  kernel_.place_every_sphere = !obstacles_.grids.empty();  // the mesh pass (TestLanes) reads them
  // Per self pair: when one link carries the other, only the dofs between them move one relative to the other.
  for (const auto& [pa, pb] : spheres_.self_pairs) {
    PairMotion motion;
    for (const uint32_t deep : {pa, pb}) {
      const uint32_t other = deep == pa ? pb : pa;
      for (int l = links[deep].parent; l >= 0; l = links[l].parent) {
        if (l == static_cast<int>(other)) {
          motion.descendant = static_cast<int>(deep);
          motion.first_dof = spheres_.group[other] + 1;
          motion.last_dof = spheres_.group[deep];
        }
      }
    }
    pair_motion_.push_back(motion);
  }
  lanes_.assign(std::max<size_t>(arm_.dof(), 1) * kernel::kLanes, 0.0f);
  scratch_.assign(kernel::ScratchSize(kernel_), 0.0f);
  centres_.resize(radii_.size());
  poses_.resize(links.size());
}

void CollisionChecker::SetLane(int lane, const Eigen::Ref<const VecX>& a, const Eigen::Ref<const VecX>& b, double t,
                               double inflate) const {
  for (size_t i = 0; i < arm_.dof(); ++i) lanes_[i * kernel::kLanes + lane] = static_cast<float>(a[i] + t * (b[i] - a[i]));
  inflate_[lane] = static_cast<float>(inflate);
}

uint32_t CollisionChecker::TestLanes(int count, uint32_t stop) const {
  for (int lane = count; lane < kernel::kLanes; ++lane) {
    for (size_t i = 0; i < arm_.dof(); ++i) lanes_[i * kernel::kLanes + lane] = lanes_[i * kernel::kLanes];
    inflate_[lane] = inflate_[0];
  }
  checks_ += count;
  const uint32_t used = (1u << count) - 1;
  stop &= used;
  uint32_t hits = kernel::CollidingLanes(kernel_, lanes_.data(), inflate_, scratch_.data(), kernel::StopLanes{stop});
  hits &= used;
  if (obstacles_.grids.empty() || (hits & stop) != 0) return hits;
  // Meshes: the spheres the kernel placed (all of them: Model::place_every_sphere is set when there are meshes),
  // lane by lane for the lanes still free, against each distance grid's lower bound.
  const float* centres = kernel::SphereCentres(kernel_, scratch_.data());
  for (int lane = 0; lane < count; ++lane) {
    if (hits & (1u << lane)) continue;
    for (size_t l = 0; l < kernel_links_.size() && !(hits & (1u << lane)); ++l) {
      if (!kernel_links_[l].against_obstacles) continue;
      for (int32_t s = kernel_links_[l].sphere_begin; s < kernel_links_[l].sphere_end; ++s) {
        const Vec3 c(centres[(3 * s) * kernel::kLanes + lane], centres[(3 * s + 1) * kernel::kLanes + lane],
                     centres[(3 * s + 2) * kernel::kLanes + lane]);
        const double r = radii_[s] + inflate_[lane] * link_inflation_[l];
        bool touches = false;
        for (const auto& grid : obstacles_.grids) touches = touches || grid.grid->LowerBound(grid.world_to_mesh * c) < r;
        if (touches) {
          hits |= 1u << lane;
          break;
        }
      }
    }
    if ((hits & stop) != 0) return hits;
  }
  return hits;
}

double CollisionChecker::ScaleInflation(const Eigen::Ref<const VecX>& a, const Eigen::Ref<const VecX>& b) const {
  const size_t links = spheres_.links.size();
  std::vector<double>& travel = link_travel_;
  travel.assign(links, 0.0);
  double largest = 0;
  for (size_t l = 0; l < links; ++l) {
    for (size_t d = 0; d < arm_.dof(); ++d) travel[l] += std::abs(b[d] - a[d]) * spheres_.link_lever[d][l];
    largest = std::max(largest, travel[l]);
  }
  if (largest <= 0) return 0;
  for (size_t l = 0; l < links; ++l) link_inflation_[l] = static_cast<float>(travel[l] / largest);
  for (size_t p = 0; p < pair_motion_.size(); ++p) {
    const PairMotion& m = pair_motion_[p];
    double relative = 0;
    if (m.descendant < 0) {
      relative = travel[spheres_.self_pairs[p].first] + travel[spheres_.self_pairs[p].second];
    } else {
      for (int d = m.first_dof; d <= m.last_dof; ++d) relative += std::abs(b[d] - a[d]) * spheres_.link_lever[d][m.descendant];
    }
    // The float rounding of the ratio must not shrink the inflation below what the bound asks.
    pair_inflation_[p] = static_cast<float>(relative / largest) * 1.0001f;
  }
  for (float& scale : link_inflation_) scale *= 1.0001f;
  return largest;
}

bool CollisionChecker::WithinLimits(const Eigen::Ref<const VecX>& q) const {
  if (q.size() != static_cast<long>(arm_.dof())) {
    ThrowInvalidArgument("configuration: " + std::to_string(q.size()) + " joint positions for an arm of " +
                         std::to_string(arm_.dof()));
  }
  for (size_t i = 0; i < arm_.dof(); ++i) {
    if (!(q[i] >= arm_.lower()[i] && q[i] <= arm_.upper()[i])) return false;
  }
  return true;
}

bool CollisionChecker::IsValid(const Eigen::Ref<const VecX>& q) const {
  if (!WithinLimits(q)) return false;
  SetLane(0, q, q, 0, 0);
  return TestLanes(1, 1u) == 0;
}

bool CollisionChecker::IsMotionValid(const Eigen::Ref<const VecX>& a, const Eigen::Ref<const VecX>& b) const {
  if (!WithinLimits(a) || !WithinLimits(b)) return false;
  const double travel = ScaleInflation(a, b);  // the most any point moves; inflation scaled per link and pair
  // Intervals [t0, t1] of the segment, each covered when both its ends pass inflated by (t1 - t0) travel / 2.
  // Round one: intervals of kCoarseSteps · resolution of travel, every end tested exactly too: a motion into an
  // obstacle (most motions a search tries in clutter) then ends at its first batch, where the inflated tests
  // alone would fail and ask for the exact ones a round later.
  // Each round tests what the intervals need, then halves the intervals not covered; a point that fails
  // inflated is also tested exactly in the next round, and one that touches exactly ends the motion.
  const int64_t coarse = std::max<int64_t>(1, static_cast<int64_t>(std::ceil(travel / (kCoarseSteps * resolution_))));
  const double smallest = resolution_ * std::ldexp(1.0, -kMaxHalvings);  // of travel
  intervals_.clear();
  for (int64_t i = 0; i < coarse; ++i) {
    intervals_.push_back(
        {static_cast<double>(i) / coarse, static_cast<double>(i + 1) / coarse, kFailedInflated, kFailedInflated});
  }
  while (!intervals_.empty()) {
    tests_.clear();
    const auto need = [&](double t, float inflate) {
      // A point shared with the previous interval was queued last (or just before its exact test).
      for (size_t i = tests_.size(); i > 0 && i + 2 > tests_.size(); --i) {
        if (tests_[i - 1].t == t && tests_[i - 1].inflate == inflate) return static_cast<int32_t>(i - 1);
      }
      tests_.push_back({t, inflate, false});
      return static_cast<int32_t>(tests_.size() - 1);
    };
    for (Interval& interval : intervals_) {
      const float inflate = static_cast<float>(0.5 * travel * (interval.t1 - interval.t0));
      interval.exact0 = interval.pass0 == kFailedInflated ? need(interval.t0, 0.0f) : -1;
      interval.test0 = interval.pass0 < inflate ? need(interval.t0, inflate) : -1;
      interval.exact1 = interval.pass1 == kFailedInflated ? need(interval.t1, 0.0f) : -1;
      interval.test1 = interval.pass1 < inflate ? need(interval.t1, inflate) : -1;
    }
    // The exact tests first, spread along the motion (bit-reversed order): a motion through an obstacle is then
    // most often refused by its first batch. The order changes which batch finds a touch, never the answer.
    exact_tests_.clear();
    for (size_t i = 0; i < tests_.size(); ++i) {
      if (tests_[i].inflate == 0.0f) exact_tests_.push_back(static_cast<uint32_t>(i));
    }
    const size_t exact_count = exact_tests_.size();
    order_.clear();
    AppendSpreadOut(exact_tests_, &order_);
    for (size_t i = 0; i < tests_.size(); ++i) {
      if (tests_[i].inflate != 0.0f) order_.push_back(static_cast<uint32_t>(i));
    }
    for (size_t first = 0; first < order_.size(); first += kernel::kLanes) {
      const int count = static_cast<int>(std::min<size_t>(kernel::kLanes, order_.size() - first));
      for (int lane = 0; lane < count; ++lane) {
        const PointTest& test = tests_[order_[first + lane]];
        SetLane(lane, a, b, test.t, test.inflate);
      }
      // Lanes tested as they are: one that touches decides the motion.
      const uint32_t exact = first >= exact_count ? 0u : (1u << std::min<size_t>(count, exact_count - first)) - 1;
      const uint32_t hits = TestLanes(count, exact);
      if ((hits & exact) != 0) return false;  // touches as it is
      for (int lane = 0; lane < count; ++lane) tests_[order_[first + lane]].touches = (hits >> lane) & 1u;
    }
    next_.clear();
    for (Interval& interval : intervals_) {
      const float inflate = static_cast<float>(0.5 * travel * (interval.t1 - interval.t0));
      const auto update = [&](int32_t test, int32_t exact, float* pass) {
        if (exact >= 0) *pass = 0.0f;  // passed exactly (a touch has returned above)
        if (test < 0) return;
        if (!tests_[test].touches) {
          *pass = std::max(*pass, inflate);
        } else if (*pass < 0) {
          *pass = kFailedInflated;
        }
      };
      update(interval.test0, interval.exact0, &interval.pass0);
      update(interval.test1, interval.exact1, &interval.pass1);
      if (interval.pass0 >= inflate && interval.pass1 >= inflate) continue;  // covered
      if (travel * (interval.t1 - interval.t0) < smallest) return false;    // too close to call: a conservative no
      const double mid = 0.5 * (interval.t0 + interval.t1);
      next_.push_back({interval.t0, mid, interval.pass0, kUnknown});
      next_.push_back({mid, interval.t1, kUnknown, interval.pass1});
    }
    intervals_.swap(next_);
  }
  return true;
}

void CollisionChecker::PlaceSpheres(const Eigen::Ref<const VecX>& q) const {
  arm_.LinkTransforms(q, &poses_);
  for (size_t l = 0; l < spheres_.links.size(); ++l) {
    const LinkSpheres& link = spheres_.links[l];
    if (link.bound_radius < 0) continue;
    for (uint32_t s = sphere_begin_[l]; s < sphere_begin_[l + 1]; ++s) {
      centres_[s] = poses_[l] * link.centres[s - sphere_begin_[l]];
    }
  }
}

bool CollisionChecker::FindContact(uint32_t* link_out, int64_t* other_out) const {
  for (uint32_t l = 0; l < spheres_.links.size(); ++l) {
    if (spheres_.links[l].bound_radius < 0 || spheres_.group[l] < 0) continue;  // no geometry / the mounting
    for (uint32_t s = sphere_begin_[l]; s < sphere_begin_[l + 1]; ++s) {
      const Vec3& c = centres_[s];
      const double r = radii_[s];
      int64_t body = -1;
      for (const auto& box : obstacles_.boxes) {
        if (body < 0 && BallTouchesBox(c, r, box)) body = box.body;
      }
      for (const auto& ball : obstacles_.balls) {
        if (body < 0 && (c - ball.centre).norm() < r + ball.radius) body = ball.body;
      }
      for (const auto& cylinder : obstacles_.cylinders) {
        if (body < 0 && BallTouchesCylinder(c, r, cylinder)) body = cylinder.body;
      }
      for (const auto& grid : obstacles_.grids) {
        if (body < 0 && grid.grid->LowerBound(grid.world_to_mesh * c) < r) body = grid.body;
      }
      if (body >= 0) {
        *link_out = l;
        *other_out = body;
        return true;
      }
    }
  }
  for (const auto& [a, b] : spheres_.self_pairs) {
    for (uint32_t i = sphere_begin_[a]; i < sphere_begin_[a + 1]; ++i) {
      for (uint32_t j = sphere_begin_[b]; j < sphere_begin_[b + 1]; ++j) {
        if ((centres_[i] - centres_[j]).norm() < radii_[i] + radii_[j]) {
          *link_out = a;
          *other_out = -static_cast<int64_t>(b) - 1;
          return true;
        }
      }
    }
  }
  return false;
}

std::string CollisionChecker::Explain(const Eigen::Ref<const VecX>& q) const {
  WithinLimits(q);  // throws on a wrong size
  for (size_t i = 0; i < arm_.dof(); ++i) {
    if (!(q[i] >= arm_.lower()[i] && q[i] <= arm_.upper()[i])) {
      return arm_.joint_ids()[i] + " = " + Short(q[i]) + " is outside its limits [" + Short(arm_.lower()[i]) + ", " +
             Short(arm_.upper()[i]) + "]";
    }
  }
  if (IsValid(q)) return "";
  // The same test in double precision, to name the pair.
  PlaceSpheres(q);
  uint32_t link;
  int64_t other;
  if (!FindContact(&link, &other)) return "a sphere of the arm is within the float margin (0.02 mm) of touching";
  const std::string& name = arm_.links()[link].id;
  if (other >= 0) return name + " touches " + obstacles_.body_ids[other];
  return name + " touches " + arm_.links()[-other - 1].id;
}

}  // namespace graspsim::motion
