#include "motion/planner.h"

#include <chrono>
#include <cmath>
#include <memory>
#include <mutex>
#include <random>

#include <ompl/base/MotionValidator.h>
#include <ompl/base/ProblemDefinition.h>
#include <ompl/base/SpaceInformation.h>
#include <ompl/base/goals/GoalStates.h>
#include <ompl/base/spaces/RealVectorStateSpace.h>
#include <ompl/geometric/PathGeometric.h>
#include <ompl/geometric/planners/rrt/RRTConnect.h>
#include <ompl/util/Console.h>

#include "core/error.h"
#include "motion/short_number.h"

namespace graspsim::motion {
namespace {

namespace ob = ompl::base;
namespace og = ompl::geometric;
using Clock = std::chrono::steady_clock;

double Seconds(Clock::time_point since) { return std::chrono::duration<double>(Clock::now() - since).count(); }

Eigen::Map<const VecX> Values(const ob::State* state, size_t n) {
  return {state->as<ob::RealVectorStateSpace::StateType>()->values, static_cast<long>(n)};
}

// OMPL's uniform sampler with its own seed, so a plan depends on PlanOptions::seed and nothing global.
class SeededSampler : public ob::RealVectorStateSampler {
 public:
  SeededSampler(const ob::StateSpace* space, uint64_t seed) : ob::RealVectorStateSampler(space) {
    rng_.setLocalSeed(static_cast<std::uint_fast32_t>(seed ^ (seed >> 32)));
  }
};

// The checker's conservative segment test as OMPL's motion validator.
class SphereMotionValidator : public ob::MotionValidator {
 public:
  SphereMotionValidator(const ob::SpaceInformationPtr& si, const CollisionChecker& checker)
      : ob::MotionValidator(si), checker_(checker), n_(checker.arm().dof()) {}
  bool checkMotion(const ob::State* a, const ob::State* b) const override {
    const bool valid = checker_.IsMotionValid(Values(a, n_), Values(b, n_));
    valid ? ++valid_ : ++invalid_;
    return valid;
  }
  bool checkMotion(const ob::State* a, const ob::State* b, std::pair<ob::State*, double>& last) const override {
    // Used by planners that extend up to the first collision; RRT-Connect does not. Bisect for the last free t.
    if (checkMotion(a, b)) return true;
    double lo = 0, hi = 1;
    for (int i = 0; i < 20; ++i) {
      const double mid = 0.5 * (lo + hi);
      si_->getStateSpace()->interpolate(a, b, mid, last.first);
      (checker_.IsMotionValid(Values(a, n_), Values(last.first, n_)) ? lo : hi) = mid;
    }
    si_->getStateSpace()->interpolate(a, b, lo, last.first);
    last.second = lo;
    return false;
  }

 private:
  const CollisionChecker& checker_;
  size_t n_;
};

void QuietOmpl() {
  static std::once_flag once;
  std::call_once(once, [] { ompl::msg::setLogLevel(ompl::msg::LOG_NONE); });
}

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

// Random: two points on two different segments joined straight when the join is free.
void ShortcutRandom(const CollisionChecker& checker, unsigned rounds, uint64_t seed, std::vector<VecX>* path) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  for (unsigned r = 0; r < rounds && path->size() > 2; ++r) {
    const size_t segments = path->size() - 1;
    size_t i = rng() % segments, j = rng() % segments;
    if (i == j) continue;
    if (i > j) std::swap(i, j);
    const VecX a = (*path)[i] + unit(rng) * ((*path)[i + 1] - (*path)[i]);
    const VecX b = (*path)[j] + unit(rng) * ((*path)[j + 1] - (*path)[j]);
    if (!checker.IsMotionValid(a, b)) continue;
    std::vector<VecX> shorter(path->begin(), path->begin() + i + 1);
    shorter.push_back(a);
    shorter.push_back(b);
    shorter.insert(shorter.end(), path->begin() + j + 1, path->end());
    *path = std::move(shorter);
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
  if (const std::string why = checker.Explain(start); !why.empty()) {
    throw Error(ErrorCode::kFailedPrecondition, "start configuration is not free: " + why);
  }
  std::vector<size_t> free_goals;
  std::string first_block;
  for (size_t g = 0; g < goals.size(); ++g) {
    const std::string why = checker.Explain(goals[g]);
    if (why.empty()) {
      free_goals.push_back(g);
    } else if (first_block.empty()) {
      first_block = why;
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
    QuietOmpl();
    auto space = std::make_shared<ob::RealVectorStateSpace>(n);
    ob::RealVectorBounds bounds(n);
    for (size_t i = 0; i < n; ++i) {
      bounds.setLow(i, arm.lower()[i]);
      bounds.setHigh(i, arm.upper()[i]);
    }
    space->setBounds(bounds);
    const uint64_t seed = options.seed;
    space->setStateSamplerAllocator(
        [seed](const ob::StateSpace* s) { return std::make_shared<SeededSampler>(s, seed); });
    auto si = std::make_shared<ob::SpaceInformation>(space);
    si->setStateValidityChecker([&checker, n](const ob::State* s) { return checker.IsValid(Values(s, n)); });
    si->setMotionValidator(std::make_shared<SphereMotionValidator>(si, checker));
    si->setup();
    auto pdef = std::make_shared<ob::ProblemDefinition>(si);
    ob::ScopedState<> from(space);
    for (size_t i = 0; i < n; ++i) from[i] = start[i];
    pdef->addStartState(from);
    auto goal_states = std::make_shared<ob::GoalStates>(si);
    for (size_t g : free_goals) {
      ob::ScopedState<> to(space);
      for (size_t i = 0; i < n; ++i) to[i] = goals[g][i];
      goal_states->addState(to);
    }
    pdef->setGoal(goal_states);
    og::RRTConnect rrt(si);
    rrt.setRange(options.range > 0 ? options.range : 0.25 * space->getMaximumExtent());
    rrt.setProblemDefinition(pdef);
    rrt.setup();
    const ob::PlannerTerminationCondition stop([&] {
      return Seconds(began) > options.timeout || (options.cancelled && options.cancelled());
    });
    const ob::PlannerStatus status = rrt.solve(stop);
    if (status != ob::PlannerStatus::EXACT_SOLUTION) {
      if (options.cancelled && options.cancelled()) {
        result.cancelled = true;
        result.checks = checker.checks() - checks_before;
        result.seconds = Seconds(began);
        return result;
      }
      throw Error(ErrorCode::kFailedPrecondition,
                  "no collision-free path found in " + Short(options.timeout) + " s of RRT-Connect (" +
                      std::to_string(checker.checks() - checks_before) +
                      " configurations checked): the goal is probably enclosed by obstacles");
    }
    const auto& states = pdef->getSolutionPath()->as<og::PathGeometric>()->getStates();
    for (const ob::State* s : states) raw.push_back(Values(s, n));
    double best = INFINITY;
    for (size_t g : free_goals) {
      const double d = (goals[g] - raw.back()).norm();
      if (d < best) best = d, result.goal_index = g;
    }
  }
  result.raw_waypoints = raw.size();
  std::vector<VecX> path = raw.size() > 2 ? ShortcutGreedy(checker, raw) : raw;
  ShortcutRandom(checker, options.shortcut_rounds, options.seed, &path);
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
