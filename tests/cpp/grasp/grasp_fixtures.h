// Objects for the grasp tests: tessellated primitives (whose exact shapes give the penetration checks an
// independent answer), and the independent penetration check itself.
#pragma once

#include <algorithm>
#include <cmath>
#include <functional>
#include <memory>
#include <vector>

#include <gtest/gtest.h>

#include "collision/tessellation.h"
#include "core/mesh.h"
#include "grasp/planner.h"

namespace graspsim::grasp::testing {

inline std::shared_ptr<const TriangleMesh> ToMesh(const collision::LocalMesh& local, const Vec3& offset = Vec3::Zero()) {
  auto mesh = std::make_shared<TriangleMesh>();
  for (const Vec3& v : local.vertices) mesh->vertices.push_back((v + offset).cast<float>());
  mesh->triangles = local.triangles;
  return mesh;
}

// Signed distance of p to a box of half extents `half` centred at the origin: > 0 outside.
inline double BoxDistance(const Vec3& p, const Vec3& half) {
  const Vec3 q = p.cwiseAbs() - half;
  return q.cwiseMax(0.0).norm() + std::min(q.maxCoeff(), 0.0);
}

// Points on the surface of a box (centre, axes, half) at `spacing`.
inline std::vector<Vec3> BoxSurface(const LinkBox& box, double spacing) {
  std::vector<Vec3> out;
  for (int axis = 0; axis < 3; ++axis) {
    const int u = (axis + 1) % 3, v = (axis + 2) % 3;
    const int nu = std::max(1, static_cast<int>(std::ceil(2 * box.half[u] / spacing)));
    const int nv = std::max(1, static_cast<int>(std::ceil(2 * box.half[v] / spacing)));
    for (int side = -1; side <= 1; side += 2) {
      for (int i = 0; i <= nu; ++i) {
        for (int j = 0; j <= nv; ++j) {
          Vec3 p;
          p[axis] = side * box.half[axis];
          p[u] = -box.half[u] + 2 * box.half[u] * i / nu;
          p[v] = -box.half[v] + 2 * box.half[v] * j / nv;
          out.push_back(box.centre + box.axes * p);
        }
      }
    }
  }
  return out;
}

// The deepest penetration between the hand of `grasp` (its links' boxes, at the grasp's pose and joints) and an
// object given by its exact signed distance `object_distance` and dense surface points `object_surface`: hand
// surface points inside the object, object surface points inside a hand box. m, >= 0.
inline double MaxPenetration(const GraspPlanner& planner, const PlannedGrasp& grasp,
                             const std::function<double(const Vec3&)>& object_distance,
                             const std::vector<Vec3>& object_surface) {
  const HandModel& hand = planner.hand();
  std::vector<Pose> poses(hand.links().size());
  hand.LinkPoses(grasp.hand_pose, grasp.joints, &poses);
  double deepest = 0;
  for (size_t l = 0; l < poses.size(); ++l) {
    for (const LinkBox& box : hand.links()[l].boxes) {
      for (const Vec3& p : BoxSurface(box, 1e-3)) deepest = std::max(deepest, -object_distance(poses[l] * p));
      const Pose inverse = poses[l].Inverse();
      for (const Vec3& q : object_surface) {
        const Vec3 local = box.axes.transpose() * (inverse * q - box.centre);
        deepest = std::max(deepest, -BoxDistance(local, box.half));
      }
    }
  }
  return deepest;
}

// A small seeded set (1.5 cm spacing, two pre-shapes, 300 candidates) planned on 2 threads, every grasp kept.
inline GraspSet PlanSmallSet(const GraspPlanner& planner, uint64_t seed = CandidateParams{}.seed) {
  CandidateParams params;
  params.seed = seed;
  params.spacing = 0.015;
  params.preshapes = {0, 1};
  params.max_candidates = 300;
  const auto set = planner.Plan(planner.Candidates(params), 0, 0, [](size_t, size_t) { return true; });
  EXPECT_TRUE(set);
  return *set;
}

}  // namespace graspsim::grasp::testing
