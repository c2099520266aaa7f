// Collision checking for planning, built for speed: the arm's sphere model (sphere_model.h) against the scene's
// obstacles as exact primitives (boxes, balls, cylinders: closed-form sphere tests) and distance grids (meshes:
// collision/distance_grid.h), with a bounding sphere per link and per obstacle as the broad phase. No allocation
// per check: link transforms and sphere centres live in buffers owned by the checker (so one checker per thread).
//
// Motions are checked conservatively, not just sampled: along a straight joint-space segment every point of the
// arm moves at most Σ_i |Δq_i| · lever_i (sphere_model.h), so with checks spaced so that no point moves more
// than `resolution` between two of them, and every arm sphere inflated by resolution / 2, the swept arm between
// two checks stays inside the inflated spheres of one of them. A valid motion therefore collides nowhere on the
// segment, not only at the checked configurations.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "collision/distance_grid.h"
#include "motion/arm.h"
#include "motion/sphere_model.h"

namespace graspsim::motion {

// Everything the arm must not touch, world frame.
struct Obstacles {
  struct Box { Mat3 rotation; Vec3 centre; Vec3 half; uint32_t body; };
  struct Ball { Vec3 centre; double radius; uint32_t body; };
  struct Cylinder { Mat3 rotation; Vec3 centre; double radius, half_length; uint32_t body; };
  struct Grid { std::shared_ptr<const DistanceGrid> grid; Rigid world_to_mesh; uint32_t body; };
  struct Bound { Vec3 centre; double radius; };  // per obstacle, same order: boxes, balls, cylinders, grids
  std::vector<Box> boxes;
  std::vector<Ball> balls;
  std::vector<Cylinder> cylinders;
  std::vector<Grid> grids;
  std::vector<std::string> body_ids;  // indexed by `body` above: SceneModel body ids
};

// Every body of the scene that is not a body of `robot_id` and not in `ignore` (ids of bodies or robots), as
// placed in `state`. Meshes get a distance grid of cell `grid_cell` m.
Obstacles CollectObstacles(const SceneModel& model, const SceneState& state, const std::string& robot_id,
                           const std::vector<std::string>& ignore = {}, double grid_cell = 0.004);

class CollisionChecker {
 public:
  // `resolution`: the most any point of the arm moves between two checks of a motion, m.
  CollisionChecker(const ArmModel& arm, ArmSphereModel spheres, Obstacles obstacles, double resolution = 0.01);

  // Within the joint limits and no inflated sphere touches an obstacle or a sphere of a self pair.
  bool IsValid(const Eigen::Ref<const VecX>& q) const;
  // Every configuration of the straight segment a -> b (a assumed valid), conservatively (see above).
  bool IsMotionValid(const Eigen::Ref<const VecX>& a, const Eigen::Ref<const VecX>& b) const;
  // Why q is not valid ("arm/link_4 touches table", "arm/joint_a2 = 3 rad is outside [-1.7, 2.4]"); "" if valid.
  std::string Explain(const Eigen::Ref<const VecX>& q) const;

  const ArmModel& arm() const { return arm_; }
  const ArmSphereModel& spheres() const { return spheres_; }
  double resolution() const { return resolution_; }
  uint64_t checks() const { return checks_; }  // configurations tested so far

 private:
  // The first touching pair at the configuration whose transforms are in poses_: obstacle body index or
  // -(link + 1) for a self pair; `link` gets the arm link. Returns false when nothing touches.
  bool FindContact(uint32_t* link, int64_t* other) const;
  void PlaceSpheres(const Eigen::Ref<const VecX>& q) const;

  const ArmModel& arm_;
  ArmSphereModel spheres_;
  Obstacles obstacles_;
  std::vector<Obstacles::Bound> bounds_;
  double resolution_, inflate_;
  std::vector<uint32_t> sphere_begin_;           // per link: first sphere in the flat arrays (size links + 1)
  std::vector<double> radii_;                    // inflated
  mutable std::vector<Rigid> poses_;
  mutable std::vector<Vec3> centres_;            // world
  mutable std::vector<Vec3> bound_centres_;      // world, per link
  mutable VecX scratch_;
  mutable uint64_t checks_ = 0;
};

}  // namespace graspsim::motion
