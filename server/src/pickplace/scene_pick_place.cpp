#include "pickplace/scene_pick_place.h"

#include "core/error.h"
#include "grasp/hand.h"
#include "grasp/plan_job.h"
#include "grasp/plan_request.h"
#include "grasp/scene_object.h"

namespace graspsim::pickplace {
namespace {

// The set the request names (checked against the hand and the object) or the default one, found in the store
// or planned now (fractions 0 … 0.2). Nullopt when cancelled.
std::optional<grasp::StoredGraspSet> GraspSetFor(const PickPlaceRequest& request, const SceneView& view,
                                                 const std::string& hand, grasp::GraspStore* store,
                                                 const SceneProgress& progress) {
  const grasp::PlanJob job =
      DefaultGraspSetJob(*view.model, view.state, request.arm_id, request.body_id, request.seed.value_or(1));
  if (request.grasp_set_id.empty()) {
    bool from_store = false;
    return grasp::FindOrPlan(
        job, store, false,
        [&](size_t done, size_t total) { return !progress || progress(Stage::kPlanGrasps, total ? 0.2 * done / total : 0); },
        &from_store);
  }
  const grasp::StoredGraspSet stored = grasp::FindStoredSet(store, "grasp_set_id", request.grasp_set_id);
  if (stored.hand != hand) {
    ThrowInvalidArgument("grasp_set_id: set '" + request.grasp_set_id + "' is for hand '" + stored.hand +
                         "', arm '" + request.arm_id + "' carries '" + hand + "'");
  }
  if (stored.mesh_hash != grasp::MeshHash(*job.mesh)) {
    ThrowInvalidArgument("grasp_set_id: set '" + request.grasp_set_id + "' was planned for another mesh than body '" +
                         request.body_id + "'");
  }
  return stored;
}

bool SameState(const SceneState& now, const SceneState& then) {
  if (now.step != then.step || now.joint_positions != then.joint_positions) return false;
  for (size_t b = 0; b < now.body_poses.size(); ++b) {
    const Pose &p = now.body_poses[b], &q = then.body_poses[b];
    if (p.position != q.position || p.orientation.coeffs() != q.orientation.coeffs()) return false;
  }
  return true;
}

}  // namespace

ScenePickPlaceResult PickAndPlaceInScene(Scene* scene, const PickPlaceRequest& request, grasp::GraspStore* store,
                                         const SceneProgress& progress) {
  if (request.arm_id.empty()) ThrowInvalidArgument("arm_id: empty; name an arm of the scene");
  if (request.body_id.empty()) ThrowInvalidArgument("body_id: empty; name the object to move");
  if (!request.goal) ThrowInvalidArgument("goal: absent; give the object's goal pose");
  if (request.max_attempts > kMaxAttempts) {
    ThrowInvalidArgument("max_attempts: " + std::to_string(request.max_attempts) + " is above " +
                         std::to_string(kMaxAttempts));
  }
  const SceneView view = scene->View();
  const std::string hand = HandOnArm(*view.model, "arm_id", request.arm_id);
  if (!request.hand_id.empty() && request.hand_id != hand) {
    grasp::LoadHand("hand_id", request.hand_id);  // an unknown name is named as such
    ThrowInvalidArgument("hand_id: '" + request.hand_id + "' is not on arm '" + request.arm_id + "' (it carries '" +
                         hand + "')");
  }
  const auto body = view.model->body_index.find(request.body_id);
  if (body == view.model->body_index.end()) {
    ThrowNotFound("body_id: no body '" + request.body_id + "' in scene '" + scene->id() + "'");
  }
  if (view.model->bodies[body->second].motion != BodyMotion::kFree) {
    ThrowInvalidArgument("body_id: '" + request.body_id + "' is not a free body; pick-and-place moves a free object");
  }
  ScenePickPlaceResult out;
  out.set_planned = request.grasp_set_id.empty();
  std::optional<grasp::StoredGraspSet> set = GraspSetFor(request, view, hand, store, progress);
  if (!set) {
    out.cancelled = true;
    return out;
  }
  out.set = std::move(*set);

  PickPlaceOptions options;
  options.max_attempts = request.max_attempts ? request.max_attempts : kDefaultAttempts;
  options.seed = request.seed.value_or(1);
  const double f0 = out.set_planned ? 0.2 : 0;
  out.run = RunPickPlace(view.model, view.state, request.arm_id, request.body_id, *request.goal, out.set.set, options,
                         [&](Stage stage, double fraction, const PickPlaceResult&) {
                           return !progress || progress(stage, f0 + (1 - f0) * fraction);
                         });
  if (out.run.cancelled) {
    out.cancelled = true;
    return out;
  }
  // Commit the simulated end state, unless the scene changed while the job ran (it would be overwritten).
  scene->Update([&](const std::shared_ptr<const SceneModel>& model, SceneState* state) {
    if (model != view.model || !SameState(*state, view.state)) {
      throw Error(ErrorCode::kFailedPrecondition,
                  "the scene changed during the pick-and-place; its result was not committed (run it again)");
    }
    *state = out.run.final_state;
  });
  return out;
}

}  // namespace graspsim::pickplace
