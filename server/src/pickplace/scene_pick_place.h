// GraspService.PickAndPlace's job on a Scene, without its stream: the request checked against the scene, the
// grasp set it names (checked against the hand and the object) or the default one found in the grasp-set store
// or planned now, RunPickPlace on a copy of the scene's state and, when the object ended at the goal, the
// simulated state committed to the scene — only if nobody changed the scene meanwhile.
#pragma once

#include <cstdint>
#include <functional>
#include <optional>
#include <string>

#include "grasp/store.h"
#include "pickplace/pick_place.h"
#include "world/scene.h"

namespace graspsim::pickplace {

constexpr uint32_t kDefaultAttempts = 5;
constexpr uint32_t kMaxAttempts = 50;

// A PickAndPlace request, decoded.
struct PickPlaceRequest {
  std::string arm_id, body_id;
  std::string hand_id;                  // "" = the arm's hand; else it must be the arm's hand
  std::string grasp_set_id;             // "" = the default set (DefaultGraspSetJob), found or planned now
  std::optional<Pose> goal;             // required
  uint32_t max_attempts = 0;            // 0 = kDefaultAttempts; at most kMaxAttempts
  std::optional<uint64_t> seed;         // absent = 1
};

struct ScenePickPlaceResult {
  bool cancelled = false;               // nothing else is set then, and the scene is unchanged
  grasp::StoredGraspSet set;            // the set the run used
  bool set_planned = false;             // the request named no set: it was found in the store or planned now
  PickPlaceResult run;
};

// `progress(stage, fraction)` as RunPickPlace's, over the whole job: planning the grasp set takes fractions
// 0 … 0.2 (Stage::kPlanGrasps) when the request names none. Returning false cancels.
using SceneProgress = std::function<bool(Stage stage, double fraction)>;

// Errors name the field: kInvalidArgument for an empty arm_id or body_id, an absent goal, max_attempts above
// kMaxAttempts, a hand_id that is not the arm's, a body that is not free, a named set for another hand or
// another mesh; kNotFound for an unknown body or set; kFailedPrecondition for a named set without a store
// (`store` null) and, after a successful run, when the scene changed while the job ran (nothing is
// committed then); and RunPickPlace's errors.
ScenePickPlaceResult PickAndPlaceInScene(Scene* scene, const PickPlaceRequest& request, grasp::GraspStore* store,
                                         const SceneProgress& progress);

}  // namespace graspsim::pickplace
