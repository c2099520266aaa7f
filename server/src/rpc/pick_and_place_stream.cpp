// GraspService.PickAndPlace: one pool job validates the request, finds or plans the grasp set (stored like
// PlanGrasps' sets), runs pickplace::RunPickPlace on a copy of the scene's state and, when the object ended at the
// goal, commits the simulated state to the scene (only if nobody changed the scene meanwhile). Progress is
// newest-only (rpc/progress_run.h); the result is the last message; a cancel stops the job at its next progress
// call (every 50 ms of simulated time, every grasp filtered, every chunk of grasp planning).
#include <cmath>
#include <memory>
#include <optional>

#include "core/error.h"
#include "grasp/hand.h"
#include "grasp/scene_object.h"
#include "pickplace/pick_place.h"
#include "rpc/convert.h"
#include "rpc/grasp_service.h"
#include "rpc/progress_run.h"
#include "rpc/run_reactor.h"

namespace graspsim::rpc {
namespace {

constexpr char kMethod[] = "GraspService/PickAndPlace";
constexpr uint32_t kDefaultAttempts = 5;
constexpr uint32_t kMaxAttempts = 50;

using PickRun = ProgressRun<v1::PickAndPlaceProgress>;

v1::PickAndPlaceProgress Message(const char* stage, double fraction) {
  v1::PickAndPlaceProgress m;
  m.set_stage(stage);
  m.set_fraction(fraction);
  return m;
}

std::string Bytes(const std::vector<double>& values) {
  return std::string(reinterpret_cast<const char*>(values.data()), values.size() * sizeof(double));
}

// The set the request names (checked against the hand and the object) or the default one, found in the store
// or planned now (fractions 0 … 0.2).
grasp::StoredGraspSet GraspSetFor(const v1::PickAndPlaceRequest& request, const SceneView& view,
                                  const std::string& hand, const std::shared_ptr<grasp::GraspStore>& store,
                                  PickRun* run, bool* cancelled) {
  const uint64_t seed = request.has_seed() ? request.seed() : 1;
  const grasp::PlanJob job =
      pickplace::DefaultGraspSetJob(*view.model, view.state, request.arm_id(), request.body_id(), seed);
  const std::string mesh_hash = grasp::MeshHash(*job.mesh);
  if (!request.grasp_set_id().empty()) {
    if (!store) {
      throw Error(ErrorCode::kFailedPrecondition, "grasp_set_id: the server stores no grasp sets (--grasp-data-dir=off)");
    }
    std::optional<grasp::StoredGraspSet> stored = store->Find(request.grasp_set_id());
    if (!stored) ThrowNotFound("grasp_set_id: no stored grasp set '" + request.grasp_set_id() + "'");
    if (stored->hand != hand) {
      ThrowInvalidArgument("grasp_set_id: set '" + request.grasp_set_id() + "' is for hand '" + stored->hand +
                           "', arm '" + request.arm_id() + "' carries '" + hand + "'");
    }
    if (stored->mesh_hash != mesh_hash) {
      ThrowInvalidArgument("grasp_set_id: set '" + request.grasp_set_id() + "' was planned for another mesh than body '" +
                           request.body_id() + "'");
    }
    return *stored;
  }
  bool from_store = false;
  std::optional<grasp::StoredGraspSet> entry = grasp::FindOrPlan(
      job, store.get(), false,
      [&](size_t done, size_t total) { return run->Progress(Message("planning_grasps", total ? 0.2 * done / total : 0)); },
      &from_store);
  if (!entry) {
    *cancelled = true;
    return grasp::StoreEntryFor(job);
  }
  return std::move(*entry);
}

void RunPick(const v1::PickAndPlaceRequest& request, const SceneRegistry* registry,
             const std::shared_ptr<grasp::GraspStore>& store, const std::shared_ptr<PickRun>& run) {
  try {
    if (request.arm_id().empty()) ThrowInvalidArgument("arm_id: empty; name an arm of the scene");
    if (request.body_id().empty()) ThrowInvalidArgument("body_id: empty; name the object to move");
    if (!request.has_goal()) ThrowInvalidArgument("goal: absent; give the object's goal pose");
    if (request.max_attempts() > kMaxAttempts) {
      ThrowInvalidArgument("max_attempts: " + std::to_string(request.max_attempts()) + " is above " +
                           std::to_string(kMaxAttempts));
    }
    const Pose goal = PoseFromProto("goal", request.goal());
    const std::shared_ptr<Scene> scene = registry->Get(request.scene_id());
    const SceneView view = scene->View();
    const std::string hand = pickplace::HandOnArm(*view.model, "arm_id", request.arm_id());
    if (!request.hand_id().empty() && request.hand_id() != hand) {
      grasp::LoadHand("hand_id", request.hand_id());  // an unknown name is named as such
      ThrowInvalidArgument("hand_id: '" + request.hand_id() + "' is not on arm '" + request.arm_id() +
                           "' (it carries '" + hand + "')");
    }
    if (!view.model->body_index.contains(request.body_id())) {
      ThrowNotFound("body_id: no body '" + request.body_id() + "' in scene '" + request.scene_id() + "'");
    }
    if (view.model->bodies[view.model->body_index.at(request.body_id())].motion != BodyMotion::kFree) {
      ThrowInvalidArgument("body_id: '" + request.body_id() + "' is not a free body; pick-and-place moves a free object");
    }
    bool cancelled = false;
    const bool planned = request.grasp_set_id().empty();
    const grasp::StoredGraspSet stored = GraspSetFor(request, view, hand, store, run.get(), &cancelled);
    if (cancelled || run->cancelled()) return;

    pickplace::PickPlaceOptions options;
    options.max_attempts = request.max_attempts() ? request.max_attempts() : kDefaultAttempts;
    options.seed = request.has_seed() ? request.seed() : 1;
    const double f0 = planned ? 0.2 : 0;
    const pickplace::PickPlaceResult result = pickplace::RunPickPlace(
        view.model, view.state, request.arm_id(), request.body_id(), goal, stored.set, options,
        [&](pickplace::Stage stage, double fraction, const pickplace::PickPlaceResult&) {
          return run->Progress(Message(pickplace::StageName(stage), f0 + (1 - f0) * fraction));
        });
    if (result.cancelled) return;  // the reactor already ends the call

    // Commit the simulated end state, unless the scene changed while the job ran (it would be overwritten).
    scene->Update([&](const std::shared_ptr<const SceneModel>& model, SceneState* state) {
      const auto same_poses = [&] {
        for (size_t b = 0; b < state->body_poses.size(); ++b) {
          const Pose &now = state->body_poses[b], &then = view.state.body_poses[b];
          if (now.position != then.position || now.orientation.coeffs() != then.orientation.coeffs()) return false;
        }
        return true;
      };
      if (model != view.model || state->step != view.state.step || state->joint_positions != view.state.joint_positions ||
          !same_poses()) {
        throw Error(ErrorCode::kFailedPrecondition,
                    "the scene changed during the pick-and-place; its result was not committed (run it again)");
      }
      *state = result.final_state;
    });

    v1::PickAndPlaceProgress last = Message("done", 1);
    last.set_success(true);
    v1::GraspSet set_proto;
    ToProto(stored.set, stored, !planned, &set_proto);
    if (result.grasp < static_cast<size_t>(set_proto.grasps_size())) *last.mutable_grasp() = set_proto.grasps(result.grasp);
    last.set_grasp_set_id(stored.key);
    last.set_grasp_index(result.grasp);
    last.set_reachable(result.reachable);
    for (const pickplace::Attempt& a : result.attempts) {
      if (!a.failure.empty()) last.add_failures("grasp " + std::to_string(a.grasp) + ": " + a.failure);
    }
    ToProto(result.object_pose, last.mutable_object_pose());
    last.set_position_error(result.position_error);
    last.set_orientation_error(result.orientation_error);
    last.set_grip_force(result.grip_force);
    last.set_simulated_seconds(result.simulated_seconds);
    for (const std::string& id : result.joint_ids) last.add_joint_ids(id);
    for (const pickplace::ArmMotion& m : result.motions) {
      v1::PickAndPlaceMotion* out = last.add_motions();
      out->set_stage(pickplace::StageName(m.stage));
      std::vector<double> rows;
      for (const motion::VecX& q : m.trajectory.waypoints()) rows.insert(rows.end(), q.data(), q.data() + q.size());
      out->set_waypoints(Bytes(rows));
      out->set_times(Bytes(m.trajectory.times()));
      out->set_closed(m.closed);
    }
    run->Finish(std::move(last), grpc::Status::OK);
  } catch (...) {
    run->Finish(std::nullopt, StatusOfException(kMethod, std::current_exception()));
  }
}

}  // namespace

grpc::ServerWriteReactor<v1::PickAndPlaceProgress>* StartPickAndPlaceStream(const v1::PickAndPlaceRequest& request,
                                                                           const SceneRegistry* registry,
                                                                           std::shared_ptr<grasp::GraspStore> store,
                                                                           WorkerPool* pool,
                                                                           grpc::CallbackServerContext* context) {
  auto* reactor = new RunReactor<v1::PickAndPlaceProgress, PickRun>(context, kMethod);
  pool->Post([request, registry, store = std::move(store), run = reactor->run()] { RunPick(request, registry, store, run); });
  return reactor;
}

}  // namespace graspsim::rpc
