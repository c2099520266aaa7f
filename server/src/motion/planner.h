// Collision-free arm paths (PAPERS.md part C: "IK, RRT-based arm path"): RRT-Connect (Kuffner & LaValle 2000) in
// joint space with the sphere-model checker (collision_checker.h) — graspsim's own search or OMPL's, on the same
// checker (search.h) — then shortcutting and time parameterisation (trajectory.h).
//
// Stages: validate (start within limits and free, at least one goal free: else FAILED_PRECONDITION naming what
// blocks it) → try the straight segment → RRT-Connect until a path, the timeout or cancellation → shortcut
// (greedy: from each waypoint jump to the farthest one in free sight; then random shortcuts) → time it.
// Every segment of the result passed the conservative motion check, so the swept arm touches nothing.
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "motion/collision_checker.h"
#include "motion/ik.h"
#include "motion/trajectory.h"

namespace graspsim::motion {

enum class Planner {
  kRrtConnect,      // graspsim's: flat trees, the batched motion check (rrt_connect.cpp)
  kOmplRrtConnect,  // OMPL's RRTConnect with its defaults on the same checker (the benchmark's reference)
};

struct PlanOptions {
  Planner planner = Planner::kRrtConnect;
  double timeout = 2.0;            // s of search before reporting that no path was found
  uint64_t seed = 1;               // same seed, same problem: same path (the search is not timed)
  double range = 0;                // RRT-Connect's longest step, rad or m (0: 1 rad for ours, OMPL's default for OMPL's)
  unsigned shortcut_rounds = 24;   // random shortcut attempts after the greedy pass
  // An attempt is checked only when it would shorten the path by at least this fraction of its length: each
  // check of a free shortcut costs a whole conservative motion check, and on the MotionBenchMaker set the smaller
  // cuts leave the mean path length as it is (docs/motion.md, step 5).
  double shortcut_min_gain = 0.005;
  bool try_direct = true;          // check the straight segment to each goal before searching
  VecX acceleration;               // per joint, rad/s²; empty: twice the velocity limit per second (no datasheet value)
  std::function<bool()> cancelled; // polled during the search
};

struct PlanResult {
  std::vector<VecX> path;          // waypoints after shortcutting, start first
  Trajectory trajectory;
  size_t goal_index = 0;           // which goal it reaches
  bool direct = false;             // the straight segment was free
  bool cancelled = false;          // stopped by `cancelled`: path empty
  size_t raw_waypoints = 0;        // before shortcutting
  uint64_t checks = 0;             // configurations tested
  uint64_t search_checks = 0;      // of which: before shortcutting (start and goals, the straight segment, RRT-Connect)
  double seconds = 0;              // wall time of the whole plan
  double search_seconds = 0;       // of which: checking start and goals, the straight segment and RRT-Connect
};

// Throws Error(kInvalidArgument) for a start or goal of the wrong size or non-finite, Error(kFailedPrecondition)
// when the start is outside the limits or collides, when every goal does, or when no path was found in time
// (each message says which and why).
PlanResult PlanPath(const CollisionChecker& checker, const VecX& start, const std::vector<VecX>& goals,
                    const PlanOptions& options = {});

// The goal as a pose of the arm's tip: every IK solution (ik.h) that is collision-free is a goal.
// FAILED_PRECONDITION when the pose is out of reach, outside the limits, or every solution collides.
PlanResult PlanPathToPose(const CollisionChecker& checker, const VecX& start, const Pose& goal,
                          const PlanOptions& options = {}, IkOptions ik_options = {});

}  // namespace graspsim::motion
