#include "rpc/plan_arm_path.h"

#include <chrono>
#include <cmath>
#include <string>

#include "core/error.h"
#include "core/format.h"
#include "motion/planner.h"
#include "rpc/call.h"
#include "rpc/convert.h"

namespace graspsim::rpc {
namespace {

motion::VecX Positions(const std::string& field, const google::protobuf::RepeatedField<double>& values,
                       const motion::ArmModel& arm) {
  if (static_cast<size_t>(values.size()) != arm.dof()) {
    ThrowInvalidArgument(field + ": " + std::to_string(values.size()) + " values for the " +
                         std::to_string(arm.dof()) + " joints of arm '" + arm.robot_id() + "'");
  }
  motion::VecX q(arm.dof());
  for (int i = 0; i < values.size(); ++i) {
    if (!std::isfinite(values[i])) {
      ThrowInvalidArgument(field + "[" + std::to_string(i) + "]: " + FormatNumber(values[i]) + " is not finite");
    }
    q[i] = values[i];
  }
  return q;
}

std::string Bytes(const std::vector<double>& values) {
  return std::string(reinterpret_cast<const char*>(values.data()), values.size() * sizeof(double));
}

// The tip's path for the viewer: each segment of the joint-space path at kTipSamples points (the tip moves on a
// curve between waypoints).
SceneOverlays::ArmPath TipPath(const motion::ArmModel& arm, const std::vector<motion::VecX>& waypoints) {
  constexpr int kTipSamples = 8;
  SceneOverlays::ArmPath path;
  path.arm_id = arm.robot_id();
  path.tip_body = arm.tip_body();
  auto add = [&](const motion::VecX& q) {
    const Vec3 p = arm.TipTransform(q).translation;
    path.tip_points.push_back({p.x(), p.y(), p.z()});
  };
  for (size_t i = 0; i < waypoints.size(); ++i) {
    if (i == 0) {
      add(waypoints[0]);
      continue;
    }
    for (int k = 1; k <= kTipSamples; ++k) add(waypoints[i - 1] + (waypoints[i] - waypoints[i - 1]) * (double(k) / kTipSamples));
  }
  return path;
}

}  // namespace

void PlanArmPath(const v1::PlanArmPathRequest& request, const SceneRegistry& registry,
                 const std::function<bool()>& cancelled, v1::PlanArmPathResponse* response,
                 SceneOverlays* overlays) {
  if (request.arm_id().empty()) ThrowInvalidArgument("arm_id: empty; name a robot of the scene");
  const bool has_pose = request.has_goal(), has_positions = request.goal_positions_size() > 0;
  if (has_pose == has_positions) {
    ThrowInvalidArgument(has_pose ? "goal, goal_positions: both given; give one"
                                  : "goal: absent; give a goal pose or goal_positions");
  }
  if (!std::isfinite(request.timeout()) || request.timeout() < 0 || request.timeout() > 60) {
    ThrowInvalidArgument("timeout: " + FormatNumber(request.timeout()) + " s is outside [0, 60] (0 = 2 s)");
  }
  const SceneView view = registry.Get(request.scene_id())->View();
  const std::string tip = request.tip_body().empty() ? "" : request.tip_body();
  const motion::ArmModel arm(*view.model, view.state, request.arm_id(), tip);
  const motion::VecX start = request.start_positions_size() > 0
                                 ? Positions("start_positions", request.start_positions(), arm)
                                 : arm.Positions(view.state);
  motion::PlanOptions options;
  if (request.planner() == "ompl_rrt_connect") {
    options.planner = motion::Planner::kOmplRrtConnect;
  } else if (!request.planner().empty() && request.planner() != "rrt_connect") {
    ThrowInvalidArgument("planner: '" + request.planner() + "' is not a planner; give \"rrt_connect\" (or empty) or "
                         "\"ompl_rrt_connect\"");
  }
  const auto setup_began = std::chrono::steady_clock::now();
  const motion::CollisionChecker checker(arm, motion::BuildSphereModel(*view.model, arm),
                                         motion::CollectObstacles(*view.model, view.state, request.arm_id()));
  const double setup_seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - setup_began).count();
  if (request.timeout() > 0) options.timeout = request.timeout();
  options.seed = request.has_seed() ? request.seed() : 1;
  options.cancelled = cancelled;
  const motion::PlanResult plan =
      has_pose ? motion::PlanPathToPose(checker, start, PoseFromProto("goal", request.goal()), options)
               : motion::PlanPath(checker, start, {Positions("goal_positions", request.goal_positions(), arm)},
                                  options);
  if (plan.cancelled) throw Error(ErrorCode::kFailedPrecondition, "cancelled");  // the call is gone anyway
  for (const std::string& id : arm.joint_ids()) response->add_joint_ids(id);
  std::vector<double> waypoints;
  for (const motion::VecX& q : plan.trajectory.waypoints()) waypoints.insert(waypoints.end(), q.data(), q.data() + q.size());
  response->set_waypoints(Bytes(waypoints));
  response->set_times(Bytes(plan.trajectory.times()));
  response->set_tip_body(arm.tip_body());
  response->set_direct(plan.direct);
  response->set_checks(plan.checks);
  response->set_seconds(plan.seconds);
  response->set_duration(plan.trajectory.duration());
  response->set_setup_seconds(setup_seconds);
  response->set_search_seconds(plan.search_seconds);
  response->set_planner(options.planner == motion::Planner::kOmplRrtConnect ? "ompl_rrt_connect" : "rrt_connect");
  if (overlays) {
    SceneOverlays::ArmPath path = TipPath(arm, plan.trajectory.waypoints());
    path.duration = plan.trajectory.duration();
    path.direct = plan.direct;
    overlays->SetArmPath(request.scene_id(), std::move(path));
  }
}

}  // namespace graspsim::rpc

namespace graspsim::rpc {

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
