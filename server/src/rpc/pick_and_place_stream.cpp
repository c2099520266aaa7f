// GraspService.PickAndPlace: one pool job decodes the request and runs pickplace::PickAndPlaceInScene (the grasp
// set found or planned, the run on a copy of the scene's state, the commit on success); this file streams its
// progress and encodes the result. Progress is newest-only (rpc/progress_run.h); the result is the last message;
// a cancel stops the job at its next progress call (every 50 ms of simulated time, every grasp filtered, every
// chunk of grasp planning).
#include <memory>
#include <optional>

#include "pickplace/scene_pick_place.h"
#include "rpc/convert.h"
#include "rpc/grasp_service.h"
#include "rpc/packed_arrays.h"
#include "rpc/progress_run.h"
#include "rpc/run_reactor.h"

namespace graspsim::rpc {
namespace {

constexpr char kMethod[] = "GraspService/PickAndPlace";

using PickRun = ProgressRun<v1::PickAndPlaceProgress>;

v1::PickAndPlaceProgress Message(const char* stage, double fraction) {
  v1::PickAndPlaceProgress m;
  m.set_stage(stage);
  m.set_fraction(fraction);
  return m;
}

void RunPick(const v1::PickAndPlaceRequest& request, const SceneRegistry* registry,
             const std::shared_ptr<grasp::GraspStore>& store, const std::shared_ptr<PickRun>& run) {
  try {
    pickplace::PickPlaceRequest pick;
    pick.arm_id = request.arm_id();
    pick.body_id = request.body_id();
    pick.hand_id = request.hand_id();
    pick.grasp_set_id = request.grasp_set_id();
    if (request.has_goal()) pick.goal = PoseFromProto("goal", request.goal());
    pick.max_attempts = request.max_attempts();
    if (request.has_seed()) pick.seed = request.seed();
    const pickplace::ScenePickPlaceResult result = pickplace::PickAndPlaceInScene(
        registry->Get(request.scene_id()).get(), pick, store.get(),
        [&](pickplace::Stage stage, double fraction) { return run->Progress(Message(pickplace::StageName(stage), fraction)); });
    if (result.cancelled) return;  // the reactor already ends the call

    const pickplace::PickPlaceResult& r = result.run;
    v1::PickAndPlaceProgress last = Message("done", 1);
    last.set_success(true);
    v1::GraspSet set_proto;
    ToProto(result.set.set, result.set, !result.set_planned, &set_proto);
    if (r.grasp < static_cast<size_t>(set_proto.grasps_size())) *last.mutable_grasp() = set_proto.grasps(r.grasp);
    last.set_grasp_set_id(result.set.key);
    last.set_grasp_index(r.grasp);
    last.set_reachable(r.reachable);
    for (const pickplace::Attempt& a : r.attempts) {
      if (!a.failure.empty()) last.add_failures("grasp " + std::to_string(a.grasp) + ": " + a.failure);
    }
    ToProto(r.object_pose, last.mutable_object_pose());
    last.set_position_error(r.position_error);
    last.set_orientation_error(r.orientation_error);
    last.set_grip_force(r.grip_force);
    last.set_simulated_seconds(r.simulated_seconds);
    for (const std::string& id : r.joint_ids) last.add_joint_ids(id);
    for (const pickplace::ArmMotion& m : r.motions) {
      v1::PickAndPlaceMotion* out = last.add_motions();
      out->set_stage(pickplace::StageName(m.stage));
      out->set_waypoints(PackRows(m.trajectory.waypoints()));
      out->set_times(Pack(m.trajectory.times()));
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
