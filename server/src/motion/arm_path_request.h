// GraspService.PlanArmPath's job on a scene, without its messages: the request checked (errors name the field),
// the arm and its collision checker built from the scene, the path planned (PlanPath or PlanPathToPose), and the
// tip's path for the viewer.
#pragma once

#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "motion/planner.h"
#include "world/scene.h"

namespace graspsim::motion {

constexpr double kMaxPlanTimeout = 60;  // s

struct ArmPathRequest {
  std::string arm_id;
  std::string tip_body;                 // "" = the arm's flange (ArmModel)
  std::optional<Pose> goal;             // exactly one of goal and goal_positions
  std::vector<double> goal_positions;
  std::vector<double> start_positions;  // empty = the scene's
  std::string planner;                  // "" or "rrt_connect", "ompl_rrt_connect"
  double timeout = 0;                   // s in [0, kMaxPlanTimeout]; 0 = PlanOptions' default (2 s)
  std::optional<uint64_t> seed;         // absent = 1
  bool tip_path = false;                // compute ArmPathPlan::tip_path
};

struct ArmPathPlan {
  std::vector<std::string> joint_ids;   // the arm's, the waypoints' columns
  std::string tip_body;
  Planner planner = Planner::kRrtConnect;
  PlanResult result;
  double setup_seconds = 0;             // building the sphere model and the obstacles
  std::vector<Vec3> tip_path;           // world, when asked for (TipPath)
};

// "rrt_connect" (or "") and "ompl_rrt_connect"; Error(kInvalidArgument) naming `field` and the value otherwise.
Planner ParsePlanner(const std::string& field, const std::string& name);
const char* PlannerName(Planner planner);

// The arm's tip along the joint-space path: the first waypoint, then each segment at `samples` points (the tip
// moves on a curve between waypoints).
std::vector<Vec3> TipPath(const ArmModel& arm, const std::vector<VecX>& waypoints, int samples = 8);

// Checks `request` (kInvalidArgument naming arm_id, goal/goal_positions, timeout, planner, start_positions[i],
// goal_positions[i]) and plans on the scene as `view` shows it; `cancelled` is polled during the search and a
// cancelled plan throws Error(kFailedPrecondition, "cancelled"). PlanPath's and ArmModel's errors otherwise.
ArmPathPlan PlanArmPathInScene(const SceneView& view, const ArmPathRequest& request,
                               const std::function<bool()>& cancelled = nullptr);

}  // namespace graspsim::motion
