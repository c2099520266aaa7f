#include "motion/arm_path_request.h"

#include <chrono>
#include <cmath>

#include "core/error.h"
#include "core/format.h"
#include "motion/sphere_model.h"

namespace graspsim::motion {
namespace {

VecX Positions(const std::string& field, const std::vector<double>& values, const ArmModel& arm) {
  if (values.size() != arm.dof()) {
    ThrowInvalidArgument(field + ": " + std::to_string(values.size()) + " values for the " + std::to_string(arm.dof()) +
                         " joints of arm '" + arm.robot_id() + "'");
  }
  VecX q(arm.dof());
  for (size_t i = 0; i < values.size(); ++i) {
    if (!std::isfinite(values[i])) {
      ThrowInvalidArgument(field + "[" + std::to_string(i) + "]: " + FormatNumber(values[i]) + " is not finite");
    }
    q[static_cast<Eigen::Index>(i)] = values[i];
  }
  return q;
}

}  // namespace

Planner ParsePlanner(const std::string& field, const std::string& name) {
  if (name.empty() || name == "rrt_connect") return Planner::kRrtConnect;
  if (name == "ompl_rrt_connect") return Planner::kOmplRrtConnect;
  ThrowInvalidArgument(field + ": '" + name + "' is not a planner; give \"rrt_connect\" (or empty) or \"ompl_rrt_connect\"");
}

const char* PlannerName(Planner planner) {
  return planner == Planner::kOmplRrtConnect ? "ompl_rrt_connect" : "rrt_connect";
}

std::vector<Vec3> TipPath(const ArmModel& arm, const std::vector<VecX>& waypoints, int samples) {
  std::vector<Vec3> points;
  for (size_t i = 0; i < waypoints.size(); ++i) {
    if (i == 0) {
      points.push_back(arm.TipTransform(waypoints[0]).translation);
      continue;
    }
    for (int k = 1; k <= samples; ++k) {
      const VecX q = waypoints[i - 1] + (waypoints[i] - waypoints[i - 1]) * (double(k) / samples);
      points.push_back(arm.TipTransform(q).translation);
    }
  }
  return points;
}

ArmPathPlan PlanArmPathInScene(const SceneView& view, const ArmPathRequest& request,
                               const std::function<bool()>& cancelled) {
  if (request.arm_id.empty()) ThrowInvalidArgument("arm_id: empty; name a robot of the scene");
  const bool has_pose = request.goal.has_value(), has_positions = !request.goal_positions.empty();
  if (has_pose == has_positions) {
    ThrowInvalidArgument(has_pose ? "goal, goal_positions: both given; give one"
                                  : "goal: absent; give a goal pose or goal_positions");
  }
  if (!std::isfinite(request.timeout) || request.timeout < 0 || request.timeout > kMaxPlanTimeout) {
    ThrowInvalidArgument("timeout: " + FormatNumber(request.timeout) + " s is outside [0, " +
                         FormatNumber(kMaxPlanTimeout) + "] (0 = 2 s)");
  }
  const ArmModel arm(*view.model, view.state, request.arm_id, request.tip_body);
  const VecX start = request.start_positions.empty() ? arm.Positions(view.state)
                                                     : Positions("start_positions", request.start_positions, arm);
  ArmPathPlan out;
  out.planner = ParsePlanner("planner", request.planner);
  PlanOptions options;
  options.planner = out.planner;
  const auto setup_began = std::chrono::steady_clock::now();
  const CollisionChecker checker(arm, BuildSphereModel(*view.model, arm),
                                 CollectObstacles(*view.model, view.state, request.arm_id));
  out.setup_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - setup_began).count();
  if (request.timeout > 0) options.timeout = request.timeout;
  options.seed = request.seed.value_or(1);
  options.cancelled = cancelled;
  out.result = has_pose ? PlanPathToPose(checker, start, *request.goal, options)
                        : PlanPath(checker, start, {Positions("goal_positions", request.goal_positions, arm)}, options);
  if (out.result.cancelled) throw Error(ErrorCode::kFailedPrecondition, "cancelled");  // the call is gone anyway
  out.joint_ids = arm.joint_ids();
  out.tip_body = arm.tip_body();
  if (request.tip_path) out.tip_path = TipPath(arm, out.result.trajectory.waypoints());
  return out;
}

}  // namespace graspsim::motion
