// The two RRT-Connect searches behind PlanPath (planner.h), on one checker: graspsim's own (rrt_connect.cpp: flat
// trees, linear nearest neighbour, the batched motion check) and OMPL's (ompl_rrt_connect.cpp: its RRTConnect with
// its default settings, the reference of the benchmark). Internal to motion/.
#pragma once

#include <chrono>
#include <vector>

#include "motion/collision_checker.h"
#include "motion/planner.h"

namespace graspsim::motion {

// RRT-Connect's longest step in joint space when PlanOptions::range is 0, rad (L2 over the arm's joints).
constexpr double kDefaultRange = 1.0;

struct SearchResult {
  std::vector<VecX> path;  // start first, ends on one of the goals; empty when not found
  bool cancelled = false;
};

// `goals`: valid goal configurations; `start` valid. Stops at options.timeout s after `began` or on cancellation.
SearchResult SearchRrtConnect(const CollisionChecker& checker, const VecX& start, const std::vector<VecX>& goals,
                              const PlanOptions& options, std::chrono::steady_clock::time_point began);
SearchResult SearchOmplRrtConnect(const CollisionChecker& checker, const VecX& start, const std::vector<VecX>& goals,
                                  const PlanOptions& options, std::chrono::steady_clock::time_point began);

}  // namespace graspsim::motion
