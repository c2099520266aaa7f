// The in-process figures of tests/bench/motion.py: 100 seeded table-top problems (an arm on a table with random
// clutter and a random object; from a pre-grasp over one spot to a pre-grasp over the object), planned by
// motion::PlanPathToPose (sphere-model checker, RRT-Connect, shortcutting, time parameterisation) and by plain
// OMPL RRT-Connect with its defaults (default range, DiscreteMotionValidator at OMPL's default resolution) and
// the exact geometry (motion::ExactChecker, ContactFinder's default 5 mm samples) on the same start and goal
// configurations. Prints one JSON object.
//
// Usage: graspsim_motion_bench [problems=100] [baseline_timeout_s=10] [resolution_m=0.01]
#include <time.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <random>
#include <string>
#include <vector>

#include <ompl/base/ProblemDefinition.h>
#include <ompl/base/SpaceInformation.h>
#include <ompl/base/goals/GoalStates.h>
#include <ompl/base/spaces/RealVectorStateSpace.h>
#include <ompl/geometric/planners/rrt/RRTConnect.h>
#include <ompl/util/Console.h>

#include "core/error.h"
#include "cpp/motion/motion_test_scenes.h"
#include "core/limits.h"
#include "motion/exact_checker.h"
#include "motion/planner.h"
#include "import/robot_import.h"
#include "world/loaders.h"
#include "world/scene.h"

namespace graspsim::motion {
namespace {

namespace ob = ompl::base;
namespace og = ompl::geometric;
using Clock = std::chrono::steady_clock;

double CpuSeconds() {
  timespec t;
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return t.tv_sec + 1e-9 * t.tv_nsec;
}

double Ms(Clock::time_point since) { return std::chrono::duration<double, std::milli>(Clock::now() - since).count(); }

using motion_test::AddStatic;

Geometry Shape(Geometry::Kind kind, const Vec3& size) {
  Geometry g;
  g.kind = kind;
  g.box_size = size;
  g.radius = 0.5 * size.x();
  g.length = size.z();
  return g;
}

constexpr double kTable = 0.75;  // m, table surface

struct Problem {
  std::unique_ptr<Scene> scene;
  SceneView view;
  std::string model;
  Pose start_pose, goal_pose;
};

// A pre-grasp: the palm facing down `height` above the table at (x, y), turned by yaw about z.
Pose PreGrasp(double x, double y, double height, double yaw) {
  return {Vec3(x, y, kTable + height),
          Quat(Eigen::AngleAxisd(yaw, Vec3::UnitZ()) * Eigen::AngleAxisd(EIGEN_PI, Vec3::UnitX()))};
}

Problem MakeProblem(uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const auto in = [&](double lo, double hi) { return lo + (hi - lo) * u(rng); };
  Problem p;
  p.model = seed % 2 ? "mitsubishi_pa10_pg70" : "kuka_kr5_sixx_r850_barrett";
  p.scene = std::make_unique<Scene>("bench", "bench", Limits());
  p.scene->AddRobot("arm", "builtin:" + p.model, LoadUrdf(BuiltinModelUrdf(p.model), nullptr, Limits()),
                    Pose{Vec3(-0.45, 0, kTable), Quat::Identity()});
  AddStatic(p.scene.get(), "table", Shape(Geometry::Kind::kBox, Vec3(1.2, 0.8, 0.04)),
            Pose{Vec3(0, 0, kTable - 0.02), Quat::Identity()});
  // Clutter: 3..8 boxes, cylinders and balls on the table in the arm's reach, not on its base.
  const int clutter = 3 + static_cast<int>(rng() % 6);
  std::vector<Vec3> placed;
  for (int i = 0; i < clutter; ++i) {
    Vec3 at;
    do {
      at = Vec3(in(-0.25, 0.55), in(-0.38, 0.38), 0);
    } while ((at.head<2>() - Eigen::Vector2d(-0.45, 0)).norm() < 0.25);
    const int kind = static_cast<int>(rng() % 3);
    const Vec3 size(in(0.04, 0.10), in(0.04, 0.10), in(0.05, 0.30));
    Geometry g = Shape(kind == 0 ? Geometry::Kind::kBox : kind == 1 ? Geometry::Kind::kCylinder : Geometry::Kind::kSphere,
                       size);
    const double half_height = kind == 2 ? g.radius : 0.5 * size.z();
    AddStatic(p.scene.get(), "clutter_" + std::to_string(i), g,
              Pose{Vec3(at.x(), at.y(), kTable + half_height), Quat(Eigen::AngleAxisd(in(0, EIGEN_PI), Vec3::UnitZ()))});
    placed.push_back(at);
  }
  // The object: a 5-8 cm box at a random free spot; the goal is its pre-grasp (see below).
  Vec3 object;
  bool clear;
  do {
    object = Vec3(in(-0.15, 0.45), in(-0.35, 0.35), 0);
    clear = (object.head<2>() - Eigen::Vector2d(-0.45, 0)).norm() > 0.3;
    for (const Vec3& c : placed) clear &= (c - object).norm() > 0.12;
  } while (!clear);
  const double object_height = in(0.05, 0.15);
  AddStatic(p.scene.get(), "object", Shape(Geometry::Kind::kBox, Vec3(in(0.05, 0.08), in(0.05, 0.08), object_height)),
            Pose{Vec3(object.x(), object.y(), kTable + 0.5 * object_height), Quat(Eigen::AngleAxisd(in(0, EIGEN_PI), Vec3::UnitZ()))});
  // The hand's length from the flange to its fingertips (open, straight): Barrett 84 + 50 + 70 + 55 mm, PG70
  // 97 + 60 mm; the pre-grasp leaves the fingertips 5 cm above the object's top.
  const double hand = p.model == "kuka_kr5_sixx_r850_barrett" ? 0.26 : 0.16;
  p.goal_pose = PreGrasp(object.x(), object.y(), object_height + hand + 0.05, in(-EIGEN_PI, EIGEN_PI));
  // The start: the hand over another spot, fingertips 15-30 cm above the table (where the last place left it).
  p.start_pose = PreGrasp(in(-0.1, 0.4), in(-0.35, 0.35), hand + in(0.15, 0.30), in(-EIGEN_PI, EIGEN_PI));
  p.view = p.scene->View();
  return p;
}

double Percentile(std::vector<double> v, double q) {
  if (v.empty()) return NAN;
  std::sort(v.begin(), v.end());
  const double index = q * (v.size() - 1);
  const size_t lo = static_cast<size_t>(index);
  const size_t hi = std::min(lo + 1, v.size() - 1);
  return v[lo] + (index - lo) * (v[hi] - v[lo]);
}

// Plain OMPL: RRT-Connect and the space information as OMPL sets them up, the exact checker as validity checker.
bool PlainOmpl(const ExactChecker& exact, const ArmModel& arm, const VecX& start, const std::vector<VecX>& goals,
               double timeout, double* ms) {
  const size_t n = arm.dof();
  auto space = std::make_shared<ob::RealVectorStateSpace>(n);
  ob::RealVectorBounds bounds(n);
  for (size_t i = 0; i < n; ++i) bounds.setLow(i, arm.lower()[i]), bounds.setHigh(i, arm.upper()[i]);
  space->setBounds(bounds);
  auto si = std::make_shared<ob::SpaceInformation>(space);
  si->setStateValidityChecker([&](const ob::State* s) {
    return exact.IsValid(Eigen::Map<const VecX>(s->as<ob::RealVectorStateSpace::StateType>()->values, n));
  });
  si->setup();
  auto pdef = std::make_shared<ob::ProblemDefinition>(si);
  ob::ScopedState<> from(space);
  for (size_t i = 0; i < n; ++i) from[i] = start[i];
  pdef->addStartState(from);
  auto goal_states = std::make_shared<ob::GoalStates>(si);
  for (const VecX& g : goals) {
    ob::ScopedState<> to(space);
    for (size_t i = 0; i < n; ++i) to[i] = g[i];
    goal_states->addState(to);
  }
  pdef->setGoal(goal_states);
  og::RRTConnect rrt(si);
  rrt.setProblemDefinition(pdef);
  rrt.setup();
  const Clock::time_point began = Clock::now();
  const bool solved = rrt.ob::Planner::solve(timeout) == ob::PlannerStatus::EXACT_SOLUTION;
  *ms = Ms(began);
  return solved;
}

int Run(int problems, double baseline_timeout, double resolution) {
  ompl::msg::setLogLevel(ompl::msg::LOG_NONE);
  int rrt_failed = 0;
  std::vector<double> rrt_ms, ik_ms, plan_ms, plan_cpu_ms, setup_ms, ompl_ms, ompl_ms_solved, checks, waypoints;
  int solved = 0, direct = 0, ompl_solved = 0, ompl_compared = 0;
  std::vector<std::string> failures;
  uint64_t seed = 1000;
  int rejected = 0;
  for (int k = 0; k < problems; ++k) {
    // A problem counts when the goal pose has an IK solution that the exact geometry (not our spheres) finds
    // free, and the start pose one that both find free (the start stands for where the last plan left the arm,
    // so it is free in the planner's own model too; the one nearest q = 0). Others are drawn again.
    Problem p;
    VecX start;
    IkOptions ik;
    ik.seed = k + 1;
    for (;; ++rejected) {
      p = MakeProblem(seed++);
      const ArmModel arm(*p.view.model, p.view.state, "arm", "arm/flange");
      const ExactChecker exact(*p.view.model, p.view.state, arm, BuildSphereModel(*p.view.model, arm), {}, 0.005);
      ik.near = VecX::Zero(arm.dof());
      start.resize(0);
      const CollisionChecker spheres(arm, BuildSphereModel(*p.view.model, arm, resolution),
                                     CollectObstacles(*p.view.model, p.view.state, "arm"), resolution);
      for (const VecX& q : SolveIk(arm, p.start_pose, ik).solutions) {
        if (exact.IsValid(q) && spheres.IsValid(q)) {
          start = q;
          break;
        }
      }
      if (start.size() == 0) continue;
      ik.near = start;
      const auto goals = SolveIk(arm, p.goal_pose, ik).solutions;
      if (std::any_of(goals.begin(), goals.end(), [&](const VecX& q) { return exact.IsValid(q); })) break;
    }
    const Clock::time_point setup = Clock::now();
    const ArmModel arm(*p.view.model, p.view.state, "arm", "arm/flange");
    const CollisionChecker checker(arm, BuildSphereModel(*p.view.model, arm, resolution),
                                   CollectObstacles(*p.view.model, p.view.state, "arm"), resolution);
    setup_ms.push_back(Ms(setup));
    {
      const Clock::time_point began = Clock::now();
      SolveIk(arm, p.goal_pose, ik);
      ik_ms.push_back(Ms(began));
    }
    PlanOptions options;
    options.seed = k + 1;
    const double cpu0 = CpuSeconds();
    const Clock::time_point began = Clock::now();
    PlanResult plan;
    try {
      plan = PlanPathToPose(checker, start, p.goal_pose, options, ik);
    } catch (const Error& e) {
      plan_ms.push_back(Ms(began));
      plan_cpu_ms.push_back(1e3 * (CpuSeconds() - cpu0));
      failures.push_back(std::to_string(k) + " (" + p.model + "): " + e.what());
      continue;
    }
    plan_ms.push_back(Ms(began));
    plan_cpu_ms.push_back(1e3 * (CpuSeconds() - cpu0));
    ++solved;
    direct += plan.direct;
    checks.push_back(plan.checks);
    waypoints.push_back(plan.path.size());

    // The same problem forced through RRT-Connect (no straight-segment shortcut): what the search costs.
    {
      PlanOptions search = options;
      search.try_direct = false;
      const Clock::time_point began = Clock::now();
      try {
        PlanPathToPose(checker, start, p.goal_pose, search, ik);
        rrt_ms.push_back(Ms(began));
      } catch (const Error& e) {
        ++rrt_failed;
      }
    }
    // The same start and the same (free) goal configurations for plain OMPL.
    std::vector<VecX> goals;
    for (const VecX& q : SolveIk(arm, p.goal_pose, ik).solutions) {
      if (checker.IsValid(q)) goals.push_back(q);
    }
    const ExactChecker exact(*p.view.model, p.view.state, arm, checker.spheres(), {}, 0.005);
    double ms = 0;
    const bool ok = PlainOmpl(exact, arm, start, goals, baseline_timeout, &ms);
    ++ompl_compared;
    ompl_solved += ok;
    ompl_ms.push_back(ms);  // unsolved runs count with the timeout they used up
    if (ok) ompl_ms_solved.push_back(ms);
    std::fprintf(stderr, "problem %d %s: ours %.3f ms (%s, %zu waypoints, %llu checks), plain OMPL %.1f ms%s\n", k,
                 p.model.c_str(), plan_ms.back(), plan.direct ? "direct" : "searched", plan.path.size(),
                 static_cast<unsigned long long>(plan.checks), ms, ok ? "" : " (not solved)");
  }
  const double p50 = Percentile(plan_ms, 0.5), ompl_p50 = Percentile(ompl_ms, 0.5);
  std::printf(
      "{\"problems\": %d, \"success_rate\": %.4f, \"plan_ms_p50\": %.4f, \"plan_ms_p95\": %.4f, \"plan_ms_max\": %.4f, "
      "\"plan_cpu_ms_p50\": %.4f, \"plan_cpu_ms_p95\": %.4f, \"setup_ms_p50\": %.4f, \"direct_fraction\": %.4f, "
      "\"checks_p50\": %.1f, \"waypoints_p50\": %.1f, \"ompl_default_ms_p50\": %.3f, \"ompl_default_ms_p95\": %.3f, "
      "\"ompl_default_success_rate\": %.4f, \"ompl_default_timeout_s\": %.1f, \"speedup_p50\": %.1f, "
      "\"rrt_forced_ms_p50\": %.4f, \"rrt_forced_ms_p95\": %.4f, \"rrt_forced_failures\": %d, \"resolution_m\": %.3f, \"ik_ms_p50\": %.4f, \"rejected_draws\": %d, \"failures\": [",
      problems, static_cast<double>(solved) / problems, p50, Percentile(plan_ms, 0.95),
      plan_ms.empty() ? NAN : *std::max_element(plan_ms.begin(), plan_ms.end()), Percentile(plan_cpu_ms, 0.5),
      Percentile(plan_cpu_ms, 0.95), Percentile(setup_ms, 0.5), solved ? static_cast<double>(direct) / solved : 0.0,
      Percentile(checks, 0.5), Percentile(waypoints, 0.5), ompl_p50, Percentile(ompl_ms, 0.95),
      ompl_compared ? static_cast<double>(ompl_solved) / ompl_compared : 0.0, baseline_timeout, ompl_p50 / p50, Percentile(rrt_ms, 0.5), Percentile(rrt_ms, 0.95), rrt_failed, resolution, Percentile(ik_ms, 0.5), rejected);
  for (size_t i = 0; i < failures.size(); ++i) {
    std::string text;
    for (char c : failures[i]) text += (c == '"' || c == '\\') ? ' ' : c;
    std::printf("%s\"%s\"", i ? ", " : "", text.c_str());
  }
  std::printf("]}\n");
  return 0;
}

}  // namespace
}  // namespace graspsim::motion

int main(int argc, char** argv) {
  const int problems = argc > 1 ? std::atoi(argv[1]) : 100;
  const double timeout = argc > 2 ? std::atof(argv[2]) : 10.0;
  const double resolution = argc > 3 ? std::atof(argv[3]) : 0.01;
  return graspsim::motion::Run(problems, timeout, resolution);
}
