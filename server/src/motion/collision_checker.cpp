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

size_t BitReversed(size_t rank, int bits) {
  size_t reversed = 0;
  for (int b = 0; b < bits; ++b) reversed |= ((rank >> b) & 1u) << (bits - 1 - b);
  return reversed;
}

// The ranks 0 .. 2^bits - 1 in bit-reversed order (0, n/2, n/4, 3n/4, ...), for bits up to kMaxTableBits; worked out
// once, as every motion check asks for them.
constexpr int kMaxTableBits = 12;

const std::vector<uint32_t>& BitReversedRanks(int bits) {
  static const std::vector<std::vector<uint32_t>> tables = [] {
    std::vector<std::vector<uint32_t>> out(kMaxTableBits + 1);
    for (int b = 0; b <= kMaxTableBits; ++b) {
      for (size_t rank = 0; rank < (size_t{1} << b); ++rank) out[b].push_back(static_cast<uint32_t>(BitReversed(rank, b)));
    }
    return out;
  }();
  return tables[bits];
}

// Appends 0 .. n - 1 to *out in bit-reversed order of their rank, so that any prefix samples them evenly.
void AppendSpreadOut(size_t n, std::vector<uint32_t>* out) {
  int bits = 0;
  while ((size_t{1} << bits) < n) ++bits;
  if (bits <= kMaxTableBits) {
    for (const uint32_t reversed : BitReversedRanks(bits)) {
      if (reversed < n) out->push_back(reversed);
    }
    return;
  }
  for (size_t rank = 0; rank < (size_t{1} << bits); ++rank) {
    const size_t reversed = BitReversed(rank, bits);
    if (reversed < n) out->push_back(static_cast<uint32_t>(reversed));
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
  obstacle_bounds_.resize(kernel::ObstacleBoundsSize(kernel_));
  kernel::FillObstacleBounds(kernel_, obstacle_bounds_.data());
  kernel_.obstacle_bounds = obstacle_bounds_.data();
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
  levers_.assign(links.size() * arm_.dof(), 0.0);
  for (size_t l = 0; l < links.size(); ++l) {
    for (size_t d = 0; d < arm_.dof(); ++d) levers_[l * arm_.dof() + d] = spheres_.link_lever[d][l];
  }
  travel_prefix_.assign(links.size() * arm_.dof(), 0.0);
  joint_step_.assign(arm_.dof(), 0.0);
  motion_from_.assign(arm_.dof(), 0.0);
  motion_delta_.assign(arm_.dof(), 0.0);
  lanes_.assign(std::max<size_t>(arm_.dof(), 1) * kernel::kLanes, 0.0f);
  scratch_.assign(kernel::ScratchSize(kernel_), 0.0f);
  centres_.resize(radii_.size());
  poses_.resize(links.size());
}

void CollisionChecker::SetMotion(const Eigen::Ref<const VecX>& a, const Eigen::Ref<const VecX>& b) const {
  for (size_t i = 0; i < arm_.dof(); ++i) {
    motion_from_[i] = a[i];
    motion_delta_[i] = b[i] - a[i];
  }
}

void CollisionChecker::SetLanes(const double* t, int count) const {
  // Every lane, those past `count` at lane 0's t (as FillLanes would copy them), so the loop over lanes has a
  // constant length and is vectorised.
  double at[kernel::kLanes];
  for (int lane = 0; lane < kernel::kLanes; ++lane) at[lane] = t[lane < count ? lane : 0];
  for (size_t i = 0; i < arm_.dof(); ++i) {
    const double from = motion_from_[i], delta = motion_delta_[i];
    float* row = lanes_.data() + i * kernel::kLanes;
    for (int lane = 0; lane < kernel::kLanes; ++lane) row[lane] = static_cast<float>(from + at[lane] * delta);
  }
}

uint32_t CollisionChecker::FillLanes(int count) const {
  for (int lane = count; lane < kernel::kLanes; ++lane) {
    for (size_t i = 0; i < arm_.dof(); ++i) lanes_[i * kernel::kLanes + lane] = lanes_[i * kernel::kLanes];
    inflate_[lane] = inflate_[0];
  }
  checks_ += count;
  return (1u << count) - 1;
}

uint32_t CollisionChecker::TestLanes(int count, uint32_t stop) const {
  const uint32_t used = FillLanes(count);
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
  const size_t links = spheres_.links.size(), dof = arm_.dof();
  if (dof == 0) return 0;
  double* step = joint_step_.data();
  for (size_t d = 0; d < dof; ++d) step[d] = std::abs(b[d] - a[d]);
  // Per link the travel of the dofs up to each one (prefix sums): a link's whole travel is its last, and a pair's
  // relative motion (the dofs between its links) a difference of two, instead of a sum per pair.
  double* travel = travel_prefix_.data();
  double largest = 0;
  for (size_t l = 0; l < links; ++l) {
    const double* lever = levers_.data() + l * dof;
    double* prefix = travel + l * dof;
    double t = 0;
    for (size_t d = 0; d < dof; ++d) prefix[d] = t += step[d] * lever[d];
    largest = std::max(largest, t);
  }
  if (largest <= 0) return 0;
  const auto whole = [&](size_t l) { return travel[l * dof + dof - 1]; };
  const double inverse = 1.0 / largest;
  for (size_t l = 0; l < links; ++l) link_inflation_[l] = static_cast<float>(whole(l) * inverse * 1.0001);
  for (size_t p = 0; p < pair_motion_.size(); ++p) {
    const PairMotion& m = pair_motion_[p];
    double relative = 0;
    if (m.descendant < 0) {
      relative = whole(spheres_.self_pairs[p].first) + whole(spheres_.self_pairs[p].second);
    } else if (m.last_dof >= m.first_dof) {
      const double* prefix = travel + static_cast<size_t>(m.descendant) * dof;
      relative = prefix[m.last_dof] - (m.first_dof > 0 ? prefix[m.first_dof - 1] : 0.0);
    }
    // The float rounding of the ratio must not shrink the inflation below what the bound asks.
    pair_inflation_[p] = static_cast<float>(relative * inverse) * 1.0001f;
  }
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
  SetMotion(q, q);
  const double t = 0;
  SetLanes(&t, 1);
  inflate_[0] = 0;
  return TestLanes(1, 1u) == 0;
}

uint32_t CollisionChecker::MeasureLanes(int count, uint32_t stop) const {
  const uint32_t used = FillLanes(count);
  stop &= used;
  uint32_t hits =
      kernel::ClearanceLanes(kernel_, lanes_.data(), inflate_, scratch_.data(), clearance_, kernel::StopLanes{stop});
  hits &= used;
  if (obstacles_.grids.empty() || (hits & stop) != 0) return hits;
  // Meshes: each free lane's spheres (all placed: Model::place_every_sphere) against each distance grid's lower
  // bound, lowering the lane's clearance as the kernel does.
  const float* centres = kernel::SphereCentres(kernel_, scratch_.data());
  for (int lane = 0; lane < count; ++lane) {
    if (hits & (1u << lane)) continue;
    double c = clearance_[lane];
    for (size_t l = 0; l < kernel_links_.size() && c >= 0; ++l) {
      if (!kernel_links_[l].against_obstacles) continue;
      const double scale = std::max<double>(link_inflation_[l], 1e-12);
      for (int32_t s = kernel_links_[l].sphere_begin; s < kernel_links_[l].sphere_end && c >= 0; ++s) {
        const Vec3 p(centres[(3 * s) * kernel::kLanes + lane], centres[(3 * s + 1) * kernel::kLanes + lane],
                     centres[(3 * s + 2) * kernel::kLanes + lane]);
        for (const auto& grid : obstacles_.grids) {
          c = std::min(c, (grid.grid->LowerBound(grid.world_to_mesh * p) - radii_[s]) / scale);
        }
      }
    }
    clearance_[lane] = static_cast<float>(c);
    if (c < 0) hits |= 1u << lane;
    if ((hits & stop) != 0) return hits;
  }
  return hits;
}

bool CollisionChecker::IsMotionValid(const Eigen::Ref<const VecX>& a, const Eigen::Ref<const VecX>& b) const {
  if (!WithinLimits(a) || !WithinLimits(b)) return false;
  const double travel = ScaleInflation(a, b);  // the most any point moves; clearance scaled per link and pair
  if (travel <= 0) return IsValid(a);
  // Points along the segment, each measured up to a cap: a point at t with clearance c (m of the largest link's
  // travel) covers [t - c / travel, t + c / travel]. Round one spaces points kCoarseSteps resolutions of travel
  // apart (at least a batch of them); each round then places points in what the last left uncovered, as many per
  // gap as fill a batch, until nothing is uncovered (free), a point touches (not free) or a gap is below the
  // smallest step. A point's cap is what it needs to cover its share of the gap: measuring farther would only
  // let more obstacles past the kernel's broad phase.
  SetMotion(a, b);
  const double smallest = resolution_ * std::ldexp(1.0, -kMaxHalvings) / travel;  // of t
  const int64_t coarse = static_cast<int64_t>(std::ceil(travel / (kCoarseSteps * resolution_)));
  const int64_t first_points = (coarse + kernel::kLanes) / kernel::kLanes * kernel::kLanes;  // >= coarse + 1
  samples_.clear();
  pending_.clear();
  const double spacing = 1.0 / static_cast<double>(first_points - 1);
  for (int64_t i = 0; i < first_points; ++i) {
    samples_.push_back({std::min(1.0, static_cast<double>(i) * spacing), 0.0f});
    pending_.push_back({static_cast<uint32_t>(i), static_cast<float>(kCoverShare * spacing * travel)});
  }
  while (!pending_.empty()) {
    // Measured spread along the segment (bit-reversed order), each batch stopping at its first touch: a motion
    // into an obstacle is most often refused by its first batch.
    order_.clear();
    AppendSpreadOut(pending_.size(), &order_);
    for (size_t first = 0; first < order_.size(); first += kernel::kLanes) {
      const int count = static_cast<int>(std::min<size_t>(kernel::kLanes, order_.size() - first));
      double t[kernel::kLanes];
      for (int lane = 0; lane < count; ++lane) {
        const Pending& p = pending_[order_[first + lane]];
        t[lane] = samples_[p.sample].t;
        inflate_[lane] = p.cap;
      }
      SetLanes(t, count);
      if (MeasureLanes(count, (1u << count) - 1) != 0) return false;  // touches as it is
      for (int lane = 0; lane < count; ++lane) samples_[pending_[order_[first + lane]].sample].clearance = clearance_[lane];
    }
    // The gaps the samples leave, and new points in them.
    gaps_.clear();
    for (size_t i = 0; i + 1 < samples_.size(); ++i) {
      const double from = samples_[i].t + samples_[i].clearance / travel;
      const double to = samples_[i + 1].t - samples_[i + 1].clearance / travel;
      if (from >= to) continue;  // covered
      if (to - from < smallest) return false;  // too close to call: a conservative no
      gaps_.push_back({i, from, to});
    }
    pending_.clear();
    if (gaps_.empty()) break;
    const size_t per_gap = std::max<size_t>(1, kernel::kLanes / gaps_.size());
    next_samples_.clear();
    size_t gap = 0;
    for (size_t i = 0; i < samples_.size(); ++i) {
      next_samples_.push_back(samples_[i]);
      if (gap < gaps_.size() && gaps_[gap].after == i) {
        const double step = (gaps_[gap].to - gaps_[gap].from) / static_cast<double>(per_gap);
        for (size_t k = 0; k < per_gap; ++k) {
          pending_.push_back({static_cast<uint32_t>(next_samples_.size()), static_cast<float>(kCoverShare * step * travel)});
          next_samples_.push_back({gaps_[gap].from + (static_cast<double>(k) + 0.5) * step, 0.0f});
        }
        ++gap;
      }
    }
    samples_.swap(next_samples_);
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
