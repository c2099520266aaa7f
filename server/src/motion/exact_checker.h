// The reference collision check: the arm's real collision geometry (boxes, cylinders, spheres, meshes — not its
// spheres) against the scene's, through collision's ContactFinder (surface samples every `spacing` m tested
// against exact primitive distances and Embree mesh queries, both ways). Slow and exact to the sample spacing:
// the tests' dense re-check of planned paths, and the plain-OMPL baseline of the motion benchmark.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "collision/contact_finder.h"
#include "motion/arm.h"
#include "motion/sphere_model.h"

namespace graspsim::motion {

class ExactChecker {
 public:
  // Obstacles as in CollectObstacles (every body not of the arm's robot and not in `ignore`), met by every link
  // that moves; self-collisions between the link pairs of `spheres.self_pairs`.
  ExactChecker(const SceneModel& model, const SceneState& state, const ArmModel& arm, const ArmSphereModel& spheres,
               const std::vector<std::string>& ignore = {}, double spacing = 0.002);
  ~ExactChecker();

  bool IsValid(const Eigen::Ref<const VecX>& q) const { return Explain(q).empty(); }
  // "" when q is within the limits and collision-free, else what touches what.
  std::string Explain(const Eigen::Ref<const VecX>& q) const;

 private:
  const ArmModel& arm_;
  std::unique_ptr<SceneModel> model_;             // arm links (free) first, then obstacles (static)
  std::unique_ptr<ContactFinder> finder_;
  std::vector<std::vector<bool>> self_pair_;      // per arm link pair: checked?
  std::vector<bool> base_link_;                   // per arm link: rigid on the base (its contacts with the scene
                                                  // are the mounting, as in CollisionChecker)
  mutable std::vector<Pose> poses_;
  mutable std::vector<Rigid> links_;
  mutable std::vector<ContactPoint> contacts_;
};

}  // namespace graspsim::motion
