#include "motion/planner.h"

#include <chrono>
#include <cmath>
#include <random>

#include "core/error.h"
#include "motion/search.h"
#include "motion/short_number.h"

namespace graspsim::motion {
namespace {

using Clock = std::chrono::steady_clock;

double Seconds(Clock::time_point since) { return std::chrono::duration<double>(Clock::now() - since).count(); }

void CheckConfiguration(const std::string& field, const CollisionChecker& checker, const VecX& q) {
  if (q.size() != static_cast<long>(checker.arm().dof())) {
    ThrowInvalidArgument(field + ": " + std::to_string(q.size()) + " joint positions for an arm of " +
                         std::to_string(checker.arm().dof()));
  }
  for (long i = 0; i < q.size(); ++i) {
    if (!std::isfinite(q[i])) ThrowInvalidArgument(field + "[" + std::to_string(i) + "] is not finite");
  }
}

// Greedy: from each waypoint straight to the farthest later one in free sight.
std::vector<VecX> ShortcutGreedy(const CollisionChecker& checker, const std::vector<VecX>& path) {
  std::vector<VecX> out = {path.front()};
  size_t i = 0;
  while (i + 1 < path.size()) {
    size_t j = path.size() - 1;
    while (j > i + 1 && !checker.IsMotionValid(path[i], path[j])) --j;
    out.push_back(path[j]);
    i = j;
  }
  return out;
}

double Length(const std::vector<VecX>& path, size_t from, size_t to) {
  double length = 0;
  for (size_t k = from; k < to; ++k) length += (path[k + 1] - path[k]).norm();
  return length;
}

// Random: two points on two different segments joined straight when the join is free and shortens the path by
// at least `min_gain` of its length. Every round draws the same numbers, checked or not.
void ShortcutRandom(const CollisionChecker& checker, unsigned rounds, double min_gain, uint64_t seed,
                    std::vector<VecX>* path) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  double length = Length(*path, 0, path->size() - 1);
  for (unsigned r = 0; r < rounds && path->size() > 2; ++r) {
    const size_t segments = path->size() - 1;
    size_t i = rng() % segments, j = rng() % segments;
    if (i == j) continue;
    if (i > j) std::swap(i, j);
    const VecX a = (*path)[i] + unit(rng) * ((*path)[i + 1] - (*path)[i]);
    const VecX b = (*path)[j] + unit(rng) * ((*path)[j + 1] - (*path)[j]);
    const double gain = ((*path)[i + 1] - a).norm() + Length(*path, i + 1, j) + (b - (*path)[j]).norm() - (b - a).norm();
    if (gain < min_gain * length || !checker.IsMotionValid(a, b)) continue;
    std::vector<VecX> shorter(path->begin(), path->begin() + i + 1);
    shorter.push_back(a);
    shorter.push_back(b);
    shorter.insert(shorter.end(), path->begin() + j + 1, path->end());
    *path = std::move(shorter);
    length -= gain;
  }
}

}  // namespace

PlanResult PlanPath(const CollisionChecker& checker, const VecX& start, const std::vector<VecX>& goals,
                    const PlanOptions& options) {
  const Clock::time_point began = Clock::now();
  const uint64_t checks_before = checker.checks();
  const ArmModel& arm = checker.arm();
  const size_t n = arm.dof();
  CheckConfiguration("start", checker, start);
  if (goals.empty()) ThrowInvalidArgument("goal: no goal configuration");
  for (size_t g = 0; g < goals.size(); ++g) CheckConfiguration("goal", checker, goals[g]);
  if (!checker.IsValid(start)) {
    throw Error(ErrorCode::kFailedPrecondition, "start configuration is not free: " + checker.Explain(start));
  }
  std::vector<size_t> free_goals;
  std::string first_block;
  for (size_t g = 0; g < goals.size(); ++g) {
    if (checker.IsValid(goals[g])) {
      free_goals.push_back(g);
    } else if (first_block.empty()) {
      first_block = checker.Explain(goals[g]);
    }
  }
  if (free_goals.empty()) {
    throw Error(ErrorCode::kFailedPrecondition,
                "goal unreachable: " + std::string(goals.size() == 1 ? "the goal configuration is blocked: "
                                                                     : "every goal configuration is blocked (first: ") +
                    first_block + (goals.size() == 1 ? "" : ")"));
  }

  PlanResult result;
  std::vector<VecX> raw;
  if (options.try_direct) {
    for (size_t g : free_goals) {
      if (checker.IsMotionValid(start, goals[g])) {
        raw = {start, goals[g]};
        result.goal_index = g;
        result.direct = true;
        break;
      }
    }
  }
  if (raw.empty()) {
    std::vector<VecX> free(free_goals.size());
    for (size_t i = 0; i < free_goals.size(); ++i) free[i] = goals[free_goals[i]];
    SearchResult search = options.planner == Planner::kOmplRrtConnect
                              ? SearchOmplRrtConnect(checker, start, free, options, began)
                              : SearchRrtConnect(checker, start, free, options, began);
    if (search.path.empty()) {
      result.checks = checker.checks() - checks_before;
      result.seconds = Seconds(began);
      if (search.cancelled) {
        result.cancelled = true;
        return result;
      }
      throw Error(ErrorCode::kFailedPrecondition,
                  "no collision-free path found in " + Short(options.timeout) + " s of RRT-Connect (" +
                      std::to_string(result.checks) + " configurations checked): the goal is probably enclosed by obstacles");
    }
    raw = std::move(search.path);
    double best = INFINITY;
    for (size_t g : free_goals) {
      const double d = (goals[g] - raw.back()).norm();
      if (d < best) best = d, result.goal_index = g;
    }
  }
  result.raw_waypoints = raw.size();
  result.search_seconds = Seconds(began);
  result.search_checks = checker.checks() - checks_before;
  std::vector<VecX> path = raw.size() > 2 ? ShortcutGreedy(checker, raw) : raw;
  ShortcutRandom(checker, options.shortcut_rounds, options.shortcut_min_gain, options.seed, &path);
  VecX acceleration = options.acceleration.size() == static_cast<long>(n) ? options.acceleration
                                                                           : VecX(2.0 * arm.velocity_limits());
  result.trajectory = Trajectory(path, arm.velocity_limits(), acceleration);
  result.path = std::move(path);
  result.checks = checker.checks() - checks_before;
  result.seconds = Seconds(began);
  return result;
}

PlanResult PlanPathToPose(const CollisionChecker& checker, const VecX& start, const Pose& goal,
                          const PlanOptions& options, IkOptions ik_options) {
  CheckConfiguration("start", checker, start);
  if (!ik_options.near) ik_options.near = start;
  const IkResult ik = SolveIk(checker.arm(), goal, ik_options);
  if (ik.solutions.empty()) throw Error(ErrorCode::kFailedPrecondition, "goal pose unreachable: " + ik.failure);
  std::vector<VecX> free;
  std::string first_block;
  for (const VecX& q : ik.solutions) {
    const std::string why = checker.Explain(q);
    if (why.empty()) {
      free.push_back(q);
    } else if (first_block.empty()) {
      first_block = why;
    }
  }
  if (free.empty()) {
    throw Error(ErrorCode::kFailedPrecondition, "goal pose unreachable: all " + std::to_string(ik.solutions.size()) +
                                                    " IK solutions collide (first: " + first_block + ")");
  }
  return PlanPath(checker, start, free, options);
}

}  // namespace graspsim::motion
