// The motion suites' independent reference for the sphere checker: the arm's spheres (BuildSphereModel) placed by
// ArmModel::LinkTransforms in double precision and tested against the obstacles by signed distances written here
// (not the checker's code), plus scenes of random primitives around a built-in arm and a kernel::Model filled by
// hand (the SIMD kernel called directly, per lane).
#pragma once

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include "motion/collision_checker.h"
#include "motion/sphere_kernel.h"
#include "motion/sphere_model.h"
#include "motion_test_scenes.h"

namespace graspsim::motion_test {

using motion::ArmModel;
using motion::ArmSphereModel;
using motion::Obstacles;
using motion::Rigid;
using motion::VecX;

// Signed distances from a point to a primitive's surface (negative inside), m.
inline double BoxDistance(const Vec3& p, const Mat3& rotation, const Vec3& centre, const Vec3& half) {
  const Vec3 d = (rotation.transpose() * (p - centre)).cwiseAbs() - half;
  const double outside = d.cwiseMax(0.0).norm();
  return outside > 0 ? outside : d.maxCoeff();
}

inline double CylinderDistance(const Vec3& p, const Mat3& rotation, const Vec3& centre, double radius,
                               double half_length) {
  const Vec3 local = rotation.transpose() * (p - centre);
  const double radial = std::sqrt(local.x() * local.x() + local.y() * local.y()) - radius;
  const double axial = std::abs(local.z()) - half_length;
  if (radial <= 0 && axial <= 0) return std::max(radial, axial);
  return std::hypot(std::max(radial, 0.0), std::max(axial, 0.0));
}

// One touching pair: an arm link and an obstacle body or (self pair) another arm link, by id.
struct Touch {
  std::string link, other;
  double clearance;  // m, < 0
};

class SphereReference {
 public:
  SphereReference(const ArmModel& arm, const ArmSphereModel& spheres, const Obstacles& obstacles)
      : arm_(arm), spheres_(spheres), obstacles_(obstacles) {}

  // World centres of every sphere, link by link (flat, in ArmSphereModel order).
  void Centres(const Eigen::Ref<const VecX>& q, std::vector<Vec3>* out) const {
    arm_.LinkTransforms(q, &poses_);
    out->clear();
    for (size_t l = 0; l < spheres_.links.size(); ++l) {
      for (const Vec3& c : spheres_.links[l].centres) out->push_back(poses_[l] * c);
    }
  }

  // The smallest clearance at q over every (moving sphere, obstacle) and self-pair sphere pair, every radius
  // grown by `inflate`, m (negative: they overlap). Links rigid on the base are not tested against obstacles
  // (their contact with the scene is the mounting, as in the checker). With `scales`, link l's spheres grow by
  // inflate * link[l] against obstacles and self pair p's two spheres together by inflate * pair[p] (the kernel's
  // Model::link_inflation / pair_inflation); without, by inflate each.
  struct Scales {
    std::vector<double> link, pair;
  };
  double Clearance(const Eigen::Ref<const VecX>& q, double inflate = 0, std::vector<Touch>* touches = nullptr,
                   const Scales* scales = nullptr) const {
    Centres(q, &centres_);
    double best = std::numeric_limits<double>::infinity();
    auto note = [&](double clearance, size_t link, const std::string& other) {
      best = std::min(best, clearance);
      if (touches && clearance < 0) touches->push_back({arm_.links()[link].id, other, clearance});
    };
    size_t s = 0;
    for (size_t l = 0; l < spheres_.links.size(); ++l) {
      const auto& link = spheres_.links[l];
      if (spheres_.group[l] < 0) {
        s += link.centres.size();
        continue;
      }
      for (size_t i = 0; i < link.centres.size(); ++i, ++s) {
        const Vec3& c = centres_[s];
        const double r = link.radii[i] + inflate * (scales ? scales->link[l] : 1.0);
        for (const auto& box : obstacles_.boxes) {
          note(BoxDistance(c, box.rotation, box.centre, box.half) - r, l, obstacles_.body_ids[box.body]);
        }
        for (const auto& ball : obstacles_.balls) {
          note((c - ball.centre).norm() - ball.radius - r, l, obstacles_.body_ids[ball.body]);
        }
        for (const auto& cylinder : obstacles_.cylinders) {
          note(CylinderDistance(c, cylinder.rotation, cylinder.centre, cylinder.radius, cylinder.half_length) - r, l,
               obstacles_.body_ids[cylinder.body]);
        }
      }
    }
    for (size_t p = 0; p < spheres_.self_pairs.size(); ++p) {
      const auto [a, b] = spheres_.self_pairs[p];
      const size_t begin_a = First(a), begin_b = First(b);
      const double grow = inflate * (scales ? scales->pair[p] : 2.0);
      for (size_t i = 0; i < spheres_.links[a].centres.size(); ++i) {
        for (size_t j = 0; j < spheres_.links[b].centres.size(); ++j) {
          note((centres_[begin_a + i] - centres_[begin_b + j]).norm() - spheres_.links[a].radii[i] -
                   spheres_.links[b].radii[j] - grow,
               a, arm_.links()[b].id);
        }
      }
    }
    return best;
  }

 private:
  size_t First(size_t link) const {
    size_t s = 0;
    for (size_t l = 0; l < link; ++l) s += spheres_.links[l].centres.size();
    return s;
  }

  const ArmModel& arm_;
  const ArmSphereModel& spheres_;
  const Obstacles& obstacles_;
  mutable std::vector<Rigid> poses_;
  mutable std::vector<Vec3> centres_;
};

inline VecX UniformConfiguration(const ArmModel& arm, std::mt19937_64* rng) {
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  VecX q(arm.dof());
  for (size_t j = 0; j < arm.dof(); ++j) q[j] = arm.lower()[j] + unit(*rng) * (arm.upper()[j] - arm.lower()[j]);
  return q;
}

inline Quat RandomRotation(std::mt19937_64* rng) {
  std::normal_distribution<double> normal(0.0, 1.0);
  return Quat(normal(*rng), normal(*rng), normal(*rng), normal(*rng)).normalized();
}

// Random boxes, balls and cylinders (3-15 cm, randomly turned), one centred on each of `centres`, ids
// "obstacle_<k>"; built here, not by CollectObstacles.
inline Obstacles RandomPrimitives(const std::vector<Vec3>& centres, std::mt19937_64* rng) {
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  const auto size = [&] { return 0.03 + 0.12 * unit(*rng); };
  Obstacles out;
  for (size_t k = 0; k < centres.size(); ++k) {
    const uint32_t body = static_cast<uint32_t>(k);
    out.body_ids.push_back("obstacle_" + std::to_string(k));
    const Mat3 rotation = RandomRotation(rng).toRotationMatrix();
    if (k % 3 == 0) {
      out.boxes.push_back({rotation, centres[k], 0.5 * Vec3(size(), size(), size()), body});
    } else if (k % 3 == 1) {
      out.balls.push_back({centres[k], 0.5 * size(), body});
    } else {
      const double radius = 0.5 * size(), length = size();
      out.cylinders.push_back({rotation, centres[k], radius, 0.5 * length, body});
    }
  }
  return out;
}

// A built-in arm (robot "arm", base at the origin) among static bodies of those primitives.
inline ArmScene SceneWith(const std::string& model, const Obstacles& o) {
  return MakeArmScene(model, Pose{}, [&](Scene* scene) {
    for (const auto& b : o.boxes) {
      AddStatic(scene, o.body_ids[b.body], BoxGeometry(2 * b.half), {b.centre, Quat(b.rotation)});
    }
    for (const auto& b : o.balls) {
      AddStatic(scene, o.body_ids[b.body], SphereGeometry(b.radius), {b.centre, Quat::Identity()});
    }
    for (const auto& c : o.cylinders) {
      AddStatic(scene, o.body_ids[c.body], CylinderGeometry(c.radius, 2 * c.half_length), {c.centre, Quat(c.rotation)});
    }
  });
}

struct RandomScene {
  ArmScene s;
  Obstacles obstacles;  // the reference's copy
};

// Obstacles near the arm: `count` random primitives, each centred 0-12 cm from a sphere of a moving link at a
// random configuration and at least half the arm's reach from its base (where the arm sweeps a large volume),
// so that random configurations both touch and miss them and many come close.
inline RandomScene NearArmScene(const std::string& model, int count, uint64_t seed) {
  const ArmScene probe = MakeArmScene(model);
  const ArmModel arm(*probe.view.model, probe.view.state, "arm");
  const ArmSphereModel spheres = BuildSphereModel(*probe.view.model, arm);
  const Obstacles none;
  const SphereReference reference(arm, spheres, none);
  std::vector<size_t> moving;  // flat sphere indices of links that move
  for (size_t l = 0, s = 0; l < spheres.links.size(); ++l) {
    for (size_t i = 0; i < spheres.links[l].centres.size(); ++i, ++s) {
      if (spheres.group[l] >= 0) moving.push_back(s);
    }
  }
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::normal_distribution<double> normal(0.0, 1.0);
  std::vector<Vec3> centres, anchors;
  double reach = 0;  // the farthest sphere centre from the base over some configurations
  for (int i = 0; i < 50; ++i) {
    reference.Centres(UniformConfiguration(arm, &rng), &centres);
    for (size_t s : moving) reach = std::max(reach, (centres[s] - arm.base().translation).norm());
  }
  while (static_cast<int>(anchors.size()) < count) {
    reference.Centres(UniformConfiguration(arm, &rng), &centres);
    const Vec3 offset(normal(rng), normal(rng), normal(rng));
    const Vec3 anchor = centres[moving[rng() % moving.size()]] + 0.12 * unit(rng) * offset.normalized();
    // Near the base an obstacle is in the way of most configurations.
    if ((anchor - arm.base().translation).norm() >= 0.5 * reach) anchors.push_back(anchor);
  }
  RandomScene out;
  out.obstacles = RandomPrimitives(anchors, &rng);
  out.s = SceneWith(model, out.obstacles);
  return out;
}

// A configuration on the segment free -> colliding whose reference clearance is `target` (bisection; the
// clearance is continuous in t).
inline VecX AtClearance(const SphereReference& reference, const VecX& free, const VecX& colliding, double target) {
  double lo = 0, hi = 1;  // clearance(lo) > target >= clearance(hi)
  for (int i = 0; i < 60; ++i) {
    const double mid = 0.5 * (lo + hi);
    (reference.Clearance(free + mid * (colliding - free)) > target ? lo : hi) = mid;
  }
  return free + lo * (colliding - free);
}

// The kernel's input filled by hand from the arm, its spheres and the obstacles, as sphere_kernel.h asks: radii
// + kFloatMargin; a revolute joint turns about its link frame's z, so each revolute link's frame is turned by A
// (A z = its axis): offset A_parent^T O A, sphere and bound centres A^T c. Owns the arrays it points into.
class KernelInput {
 public:
  KernelInput(const ArmModel& arm, const ArmSphereModel& spheres, const Obstacles& obstacles) {
    namespace k = motion::kernel;
    std::vector<Mat3> frames(arm.links().size(), Mat3::Identity());
    for (size_t l = 0; l < arm.links().size(); ++l) {
      const auto& link = arm.links()[l];
      k::Link out;
      out.parent = link.parent;
      out.dof = link.dof;
      out.kind = link.dof < 0 ? k::kRigid : (link.type == JointType::kPrismatic ? k::kPrismatic : k::kRevolute);
      if (out.kind == k::kRevolute) {
        // Any A with A z = axis: here the rotation of least angle (unlike the checker's choice).
        frames[l] = Eigen::Quaterniond::FromTwoVectors(Vec3::UnitZ(), link.axis.normalized()).toRotationMatrix();
      }
      const Mat3 parent = link.parent >= 0 ? frames[link.parent] : Mat3::Identity();
      Store(Mat3(parent.transpose() * link.offset.rotation * frames[l]), out.rotation);
      Store(Vec3(parent.transpose() * link.offset.translation), out.translation);
      Store(link.axis.normalized(), out.axis);  // used by prismatic joints, whose frames are not turned
      out.sphere_begin = static_cast<int32_t>(x_.size());
      for (size_t s = 0; s < spheres.links[l].centres.size(); ++s) {
        const Vec3 c = frames[l].transpose() * spheres.links[l].centres[s];
        x_.push_back(static_cast<float>(c.x()));
        y_.push_back(static_cast<float>(c.y()));
        z_.push_back(static_cast<float>(c.z()));
        radius_.push_back(static_cast<float>(spheres.links[l].radii[s]) + k::kFloatMargin);
      }
      out.sphere_end = static_cast<int32_t>(x_.size());
      Store(Vec3(frames[l].transpose() * spheres.links[l].bound_centre), out.bound_centre);
      out.bound_radius = spheres.links[l].bound_radius < 0
                             ? -1.0f
                             : static_cast<float>(spheres.links[l].bound_radius) + 2 * k::kFloatMargin;
      out.against_obstacles = spheres.group[l] >= 0 ? 1 : 0;
      links_.push_back(out);
    }
    for (const auto& b : obstacles.boxes) {
      k::Box out;
      Store(Mat3(b.rotation.transpose()), out.rotation_t);
      Store(b.centre, out.centre);
      Store(b.half, out.half);
      out.bound_radius = static_cast<float>(b.half.norm() * (1 + 1e-4));
      boxes_.push_back(out);
    }
    for (const auto& b : obstacles.balls) {
      k::Ball out;
      Store(b.centre, out.centre);
      out.radius = static_cast<float>(b.radius);
      balls_.push_back(out);
    }
    for (const auto& c : obstacles.cylinders) {
      k::Cylinder out;
      Store(Mat3(c.rotation.transpose()), out.rotation_t);
      Store(c.centre, out.centre);
      out.radius = static_cast<float>(c.radius);
      out.half_length = static_cast<float>(c.half_length);
      out.bound_radius = static_cast<float>(std::hypot(c.radius, c.half_length) * (1 + 1e-4));
      cylinders_.push_back(out);
    }
    for (const auto& [a, b] : spheres.self_pairs) {
      pairs_.push_back(static_cast<int32_t>(a));
      pairs_.push_back(static_cast<int32_t>(b));
    }
    model.links = links_.data();
    model.link_count = static_cast<int32_t>(links_.size());
    Store(arm.base().rotation, model.base_rotation);
    Store(arm.base().translation, model.base_translation);
    model.sphere_x = x_.data();
    model.sphere_y = y_.data();
    model.sphere_z = z_.data();
    model.sphere_radius = radius_.data();
    model.sphere_count = static_cast<int32_t>(x_.size());
    model.boxes = boxes_.data();
    model.box_count = static_cast<int32_t>(boxes_.size());
    model.balls = balls_.data();
    model.ball_count = static_cast<int32_t>(balls_.size());
    model.cylinders = cylinders_.data();
    model.cylinder_count = static_cast<int32_t>(cylinders_.size());
    model.self_pairs = pairs_.data();
    model.self_pair_count = static_cast<int32_t>(spheres.self_pairs.size());
    model.place_every_sphere = true;  // the tests compare the centres
    // The obstacles' broad phase as the checker sets it; a test may turn it off (nullptr) to compare.
    obstacle_bounds.resize(k::ObstacleBoundsSize(model));
    k::FillObstacleBounds(model, obstacle_bounds.data());
    model.obstacle_bounds = obstacle_bounds.data();
    scratch.assign(motion::kernel::ScratchSize(model), 0.0f);
  }

  motion::kernel::Model model;
  std::vector<float> scratch;
  std::vector<float> obstacle_bounds;

 private:
  static void Store(const Mat3& r, float* out) {
    for (int i = 0; i < 3; ++i) {
      for (int j = 0; j < 3; ++j) out[3 * i + j] = static_cast<float>(r(i, j));
    }
  }
  static void Store(const Vec3& v, float* out) {
    for (int i = 0; i < 3; ++i) out[i] = static_cast<float>(v[i]);
  }

  std::vector<motion::kernel::Link> links_;
  std::vector<float> x_, y_, z_, radius_;
  std::vector<motion::kernel::Box> boxes_;
  std::vector<motion::kernel::Ball> balls_;
  std::vector<motion::kernel::Cylinder> cylinders_;
  std::vector<int32_t> pairs_;
};

}  // namespace graspsim::motion_test
