#include "motion/collision_checker.h"

#include <algorithm>
#include <cmath>

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

CollisionChecker::CollisionChecker(const ArmModel& arm, ArmSphereModel spheres, Obstacles obstacles, double resolution)
    : arm_(arm), spheres_(std::move(spheres)), obstacles_(std::move(obstacles)), resolution_(resolution),
      inflate_(0.5 * resolution) {
  for (const auto& box : obstacles_.boxes) bounds_.push_back({box.centre, box.half.norm()});
  for (const auto& ball : obstacles_.balls) bounds_.push_back({ball.centre, ball.radius});
  for (const auto& c : obstacles_.cylinders) bounds_.push_back({c.centre, std::hypot(c.radius, c.half_length)});
  // A grid's bound: the ball of everything closer than its padding, from its lower bound's own frame: the
  // grid is small, so take no broad phase for it (radius infinite).
  for (size_t g = 0; g < obstacles_.grids.size(); ++g) bounds_.push_back({Vec3::Zero(), INFINITY});
  sphere_begin_.push_back(0);
  for (const LinkSpheres& link : spheres_.links) {
    for (double r : link.radii) radii_.push_back(r + inflate_);
    sphere_begin_.push_back(static_cast<uint32_t>(radii_.size()));
  }
  centres_.resize(radii_.size());
  bound_centres_.resize(spheres_.links.size());
  poses_.resize(arm_.links().size());
  scratch_.resize(arm_.dof());
}

void CollisionChecker::PlaceSpheres(const Eigen::Ref<const VecX>& q) const {
  ++checks_;
  arm_.LinkTransforms(q, &poses_);
  for (size_t l = 0; l < spheres_.links.size(); ++l) {
    const LinkSpheres& link = spheres_.links[l];
    if (link.bound_radius < 0) continue;
    bound_centres_[l] = poses_[l] * link.bound_centre;
    for (uint32_t s = sphere_begin_[l]; s < sphere_begin_[l + 1]; ++s) {
      centres_[s] = poses_[l] * link.centres[s - sphere_begin_[l]];
    }
  }
}

bool CollisionChecker::FindContact(uint32_t* link_out, int64_t* other_out) const {
  const size_t boxes = obstacles_.boxes.size(), balls = obstacles_.balls.size(),
               cylinders = obstacles_.cylinders.size();
  for (uint32_t l = 0; l < spheres_.links.size(); ++l) {
    const LinkSpheres& link = spheres_.links[l];
    // Links rigid on the base never move: where they meet the scene (the base standing on the table) no plan
    // can change it, so the arm's mounting is not a collision.
    if (link.bound_radius < 0 || spheres_.group[l] < 0) continue;
    const double link_radius = link.bound_radius + inflate_;
    for (size_t o = 0; o < bounds_.size(); ++o) {
      const double reach = link_radius + bounds_[o].radius;
      if ((bound_centres_[l] - bounds_[o].centre).squaredNorm() >= reach * reach) continue;
      // The link's bounding ball against the primitive itself: a table's bounding ball holds the whole arm.
      if (o < boxes && !BallTouchesBox(bound_centres_[l], link_radius, obstacles_.boxes[o])) continue;
      if (o >= boxes + balls && o < boxes + balls + cylinders &&
          !BallTouchesCylinder(bound_centres_[l], link_radius, obstacles_.cylinders[o - boxes - balls])) {
        continue;
      }
      for (uint32_t s = sphere_begin_[l]; s < sphere_begin_[l + 1]; ++s) {
        const Vec3& c = centres_[s];
        const double r = radii_[s];
        bool touches;
        uint32_t body;
        if (o < boxes) {
          touches = BallTouchesBox(c, r, obstacles_.boxes[o]);
          body = obstacles_.boxes[o].body;
        } else if (o < boxes + balls) {
          const auto& ball = obstacles_.balls[o - boxes];
          touches = (c - ball.centre).squaredNorm() < (r + ball.radius) * (r + ball.radius);
          body = ball.body;
        } else if (o < boxes + balls + cylinders) {
          touches = BallTouchesCylinder(c, r, obstacles_.cylinders[o - boxes - balls]);
          body = obstacles_.cylinders[o - boxes - balls].body;
        } else {
          const auto& grid = obstacles_.grids[o - boxes - balls - cylinders];
          touches = grid.grid->LowerBound(grid.world_to_mesh * c) < r;
          body = grid.body;
        }
        if (touches) {
          *link_out = l;
          *other_out = body;
          return true;
        }
      }
    }
  }
  for (const auto& [a, b] : spheres_.self_pairs) {
    const double reach = spheres_.links[a].bound_radius + spheres_.links[b].bound_radius + 2 * inflate_;
    if ((bound_centres_[a] - bound_centres_[b]).squaredNorm() >= reach * reach) continue;
    for (uint32_t i = sphere_begin_[a]; i < sphere_begin_[a + 1]; ++i) {
      for (uint32_t j = sphere_begin_[b]; j < sphere_begin_[b + 1]; ++j) {
        const double r = radii_[i] + radii_[j];
        if ((centres_[i] - centres_[j]).squaredNorm() < r * r) {
          *link_out = a;
          *other_out = -static_cast<int64_t>(b) - 1;
          return true;
        }
      }
    }
  }
  return false;
}

bool CollisionChecker::IsValid(const Eigen::Ref<const VecX>& q) const {
  for (size_t i = 0; i < arm_.dof(); ++i) {
    if (!(q[i] >= arm_.lower()[i] && q[i] <= arm_.upper()[i])) return false;
  }
  PlaceSpheres(q);
  uint32_t link;
  int64_t other;
  return !FindContact(&link, &other);
}

bool CollisionChecker::IsMotionValid(const Eigen::Ref<const VecX>& a, const Eigen::Ref<const VecX>& b) const {
  double travel = 0;
  for (size_t i = 0; i < arm_.dof(); ++i) travel += std::abs(b[i] - a[i]) * spheres_.lever[i];
  const uint64_t n = std::max<uint64_t>(1, static_cast<uint64_t>(std::ceil(travel / resolution_)));
  // The end first, then coarse to fine (bisection order): a colliding segment usually fails early.
  if (!IsValid(b)) return false;
  uint64_t top = 1;
  while (top * 2 <= n) top *= 2;
  for (uint64_t step = top; step >= 1; step /= 2) {
    for (uint64_t k = step; k < n; k += step) {
      if (step != top && k % (2 * step) == 0) continue;  // checked at a coarser level
      const double t = static_cast<double>(k) / n;
      scratch_ = a + t * (b - a);
      if (!IsValid(scratch_)) return false;
    }
  }
  return true;
}

std::string CollisionChecker::Explain(const Eigen::Ref<const VecX>& q) const {
  for (size_t i = 0; i < arm_.dof(); ++i) {
    if (!(q[i] >= arm_.lower()[i] && q[i] <= arm_.upper()[i])) {
      return arm_.joint_ids()[i] + " = " + Short(q[i]) + " is outside its limits [" + Short(arm_.lower()[i]) + ", " +
             Short(arm_.upper()[i]) + "]";
    }
  }
  PlaceSpheres(q);
  uint32_t link;
  int64_t other;
  if (!FindContact(&link, &other)) return "";
  const std::string& name = arm_.links()[link].id;
  if (other >= 0) return name + " touches " + obstacles_.body_ids[other];
  return name + " touches " + arm_.links()[-other - 1].id;
}

}  // namespace graspsim::motion
