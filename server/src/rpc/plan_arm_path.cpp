#include "rpc/plan_arm_path.h"

#include "core/error.h"
#include "motion/arm_path_request.h"
#include "rpc/call.h"
#include "rpc/convert.h"
#include "rpc/packed_arrays.h"

namespace graspsim::rpc {

void PlanArmPath(const v1::PlanArmPathRequest& request, const SceneRegistry& registry,
                 const std::function<bool()>& cancelled, v1::PlanArmPathResponse* response,
                 SceneOverlays* overlays) {
  motion::ArmPathRequest path_request;
  path_request.arm_id = request.arm_id();
  path_request.tip_body = request.tip_body();
  if (request.has_goal()) path_request.goal = PoseFromProto("goal", request.goal());
  path_request.goal_positions.assign(request.goal_positions().begin(), request.goal_positions().end());
  path_request.start_positions.assign(request.start_positions().begin(), request.start_positions().end());
  path_request.planner = request.planner();
  path_request.timeout = request.timeout();
  if (request.has_seed()) path_request.seed = request.seed();
  path_request.tip_path = overlays != nullptr;
  const motion::ArmPathPlan plan =
      motion::PlanArmPathInScene(registry.Get(request.scene_id())->View(), path_request, cancelled);
  const motion::Trajectory& trajectory = plan.result.trajectory;
  for (const std::string& id : plan.joint_ids) response->add_joint_ids(id);
  response->set_waypoints(PackRows(trajectory.waypoints()));
  response->set_times(Pack(trajectory.times()));
  response->set_tip_body(plan.tip_body);
  response->set_direct(plan.result.direct);
  response->set_checks(plan.result.checks);
  response->set_seconds(plan.result.seconds);
  response->set_duration(trajectory.duration());
  response->set_setup_seconds(plan.setup_seconds);
  response->set_search_seconds(plan.result.search_seconds);
  response->set_planner(motion::PlannerName(plan.planner));
  if (overlays) {
    SceneOverlays::ArmPath path;
    path.arm_id = request.arm_id();
    path.tip_body = plan.tip_body;
    for (const Vec3& p : plan.tip_path) path.tip_points.push_back({p.x(), p.y(), p.z()});
    path.duration = trajectory.duration();
    path.direct = plan.result.direct;
    overlays->SetArmPath(request.scene_id(), std::move(path));
  }
}

void PlanArmPaths(const v1::PlanArmPathsRequest& request, const SceneRegistry& registry,
                  const std::function<bool()>& cancelled, v1::PlanArmPathsResponse* response) {
  constexpr int kMaxProblems = 10000;
  if (request.problems_size() > kMaxProblems) {
    ThrowInvalidArgument("problems: " + std::to_string(request.problems_size()) + " problems; at most " +
                         std::to_string(kMaxProblems) + " per call");
  }
  for (const v1::PlanArmPathRequest& problem : request.problems()) {
    if (cancelled()) throw Error(ErrorCode::kFailedPrecondition, "cancelled");  // the call is gone anyway
    v1::PlanArmPathResult* result = response->add_results();
    try {
      PlanArmPath(problem, registry, cancelled, result->mutable_path());
    } catch (const Error& error) {
      result->clear_path();
      result->set_status_code(static_cast<int32_t>(ToStatus(error).error_code()));
      result->set_error(error.what());
    }
  }
}

}  // namespace graspsim::rpc
