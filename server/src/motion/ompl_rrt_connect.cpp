// OMPL's RRTConnect on graspsim's checker: the reference the benchmark compares our own search with (same
// checker, same problems). OMPL's defaults otherwise (its range: a fifth of the space's maximum extent, unless
// PlanOptions::range says otherwise; its nearest-neighbour structure), seeded sampling so a plan is repeatable.
#include <memory>
#include <mutex>

#include <ompl/base/MotionValidator.h>
#include <ompl/base/ProblemDefinition.h>
#include <ompl/base/SpaceInformation.h>
#include <ompl/base/goals/GoalStates.h>
#include <ompl/base/spaces/RealVectorStateSpace.h>
#include <ompl/geometric/PathGeometric.h>
#include <ompl/geometric/planners/rrt/RRTConnect.h>
#include <ompl/util/Console.h>

#include "motion/search.h"

namespace graspsim::motion {
namespace {

namespace ob = ompl::base;
namespace og = ompl::geometric;
using Clock = std::chrono::steady_clock;

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

}  // namespace

SearchResult SearchOmplRrtConnect(const CollisionChecker& checker, const VecX& start, const std::vector<VecX>& goals,
                                  const PlanOptions& options, Clock::time_point began) {
  QuietOmpl();
  const ArmModel& arm = checker.arm();
  const size_t n = arm.dof();
  auto space = std::make_shared<ob::RealVectorStateSpace>(n);
  ob::RealVectorBounds bounds(n);
  for (size_t i = 0; i < n; ++i) {
    bounds.setLow(i, arm.lower()[i]);
    bounds.setHigh(i, arm.upper()[i]);
  }
  space->setBounds(bounds);
  const uint64_t seed = options.seed;
  space->setStateSamplerAllocator([seed](const ob::StateSpace* s) { return std::make_shared<SeededSampler>(s, seed); });
  auto si = std::make_shared<ob::SpaceInformation>(space);
  si->setStateValidityChecker([&checker, n](const ob::State* s) { return checker.IsValid(Values(s, n)); });
  si->setMotionValidator(std::make_shared<SphereMotionValidator>(si, checker));
  si->setup();
  auto pdef = std::make_shared<ob::ProblemDefinition>(si);
  ob::ScopedState<> from(space);
  for (size_t i = 0; i < n; ++i) from[i] = start[i];
  pdef->addStartState(from);
  auto goal_states = std::make_shared<ob::GoalStates>(si);
  for (const VecX& goal : goals) {
    ob::ScopedState<> to(space);
    for (size_t i = 0; i < n; ++i) to[i] = goal[i];
    goal_states->addState(to);
  }
  pdef->setGoal(goal_states);
  og::RRTConnect rrt(si);
  if (options.range > 0) rrt.setRange(options.range);
  rrt.setProblemDefinition(pdef);
  rrt.setup();
  const ob::PlannerTerminationCondition stop([&] {
    return std::chrono::duration<double>(Clock::now() - began).count() > options.timeout ||
           (options.cancelled && options.cancelled());
  });
  SearchResult result;
  if (rrt.solve(stop) != ob::PlannerStatus::EXACT_SOLUTION) {
    result.cancelled = options.cancelled && options.cancelled();
    return result;
  }
  for (const ob::State* s : pdef->getSolutionPath()->as<og::PathGeometric>()->getStates()) result.path.emplace_back(Values(s, n));
  return result;
}

}  // namespace graspsim::motion
