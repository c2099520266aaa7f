// The in-process figures behind tests/bench/mbm.py: MotionBenchMaker's Panda problems (tests/data/mbm.py fetches
// them) planned by motion::PlanPath as the server plans them (PlanArmPathInScene: the scene's obstacles collected,
// the sphere model built, default resolution), without gRPC, so that a change to the checker or the search can be
// measured on all 700 problems in a minute, and its answers compared (the paths' total length and the
// configurations tested are printed beside the times).
//
// Usage: graspsim_mbm_bench [seeds=5] [problems_per_scene=100] [planner=rrt_connect|ompl_rrt_connect] [scene]
// (scene: only that scene's problems, e.g. "cage").
// Reads GRASPSIM_MBM_DIR like the motion suites. Prints one JSON object: search_us / plan_us p50 and p95 over
// problems (a problem's figure the median over its seeds, an unsolved run counted as the timeout), checks per plan
// p50 and p95 (of them before shortcutting: p50), the total path length (rad), solved and runs.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <fstream>
#include <string>
#include <vector>

#include "core/error.h"
#include "cpp/motion/mbm_problems.h"
#include "motion/arm_path_request.h"
#include "motion/planner.h"
#include "motion/sphere_model.h"

namespace graspsim::motion {
namespace {

using Clock = std::chrono::steady_clock;

double Percentile(std::vector<double> v, double p) {
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  const double at = p * (v.size() - 1);
  const size_t lo = static_cast<size_t>(at);
  const size_t hi = std::min(lo + 1, v.size() - 1);
  return v[lo] + (at - lo) * (v[hi] - v[lo]);
}

double Median(std::vector<double> v) { return Percentile(std::move(v), 0.5); }

int Run(int argc, char** argv) {
  const int seeds = argc > 1 ? std::atoi(argv[1]) : 5;
  const int per_scene = argc > 2 ? std::atoi(argv[2]) : 100;
  const Planner planner = ParsePlanner("planner", argc > 3 ? argv[3] : "");
  const std::string only_scene = argc > 4 ? argv[4] : "";
  const double timeout = 10.0;
  const std::string dir = motion_test::MbmDirectory();
  std::ifstream file(dir + "/problems.txt");
  std::string urdf;
  if (!file || !motion_test::ReadFile(dir + "/panda_spherized.urdf", &urdf)) {
    std::fprintf(stderr, "no problems in %s: run `%s`\n", dir.c_str(), motion_test::kMbmFetch);
    return 2;
  }
  urdf = motion_test::WithoutVisuals(urdf);
  std::vector<motion_test::MbmProblem> problems = motion_test::ParseMbmProblems(file);
  std::vector<double> search_us, plan_us, checks, search_checks;
  double length_sum = 0, plan_total_us = 0;
  int solved = 0, runs = 0, counted = 0;
  std::string scene;
  int in_scene = 0;
  for (const motion_test::MbmProblem& problem : problems) {
    in_scene = problem.scene == scene ? in_scene + 1 : 0;
    scene = problem.scene;
    if (in_scene >= per_scene || (!only_scene.empty() && problem.scene != only_scene)) continue;
    ++counted;
    const motion_test::ArmScene s = motion_test::MbmScene(problem, urdf);
    const ArmModel arm(*s.view.model, s.view.state, "panda", "panda/panda_hand");
    const CollisionChecker checker(arm, BuildSphereModel(*s.view.model, arm),
                                   CollectObstacles(*s.view.model, s.view.state, "panda"));
    std::vector<double> search, plan, tested, tested_searching;
    int problem_solved = 0;
    for (int seed = 1; seed <= seeds; ++seed) {
      PlanOptions options;
      options.planner = planner;
      options.seed = seed;
      options.timeout = timeout;
      ++runs;
      try {
        const PlanResult r = PlanPath(checker, problem.start, {problem.goal}, options);
        search.push_back(r.search_seconds * 1e6);
        plan.push_back(r.seconds * 1e6);
        tested.push_back(static_cast<double>(r.checks));
        tested_searching.push_back(static_cast<double>(r.search_checks));
        plan_total_us += r.seconds * 1e6;
        for (size_t k = 1; k < r.path.size(); ++k) length_sum += (r.path[k] - r.path[k - 1]).norm();
        ++problem_solved;
      } catch (const Error&) {
        search.push_back(timeout * 1e6);
        plan.push_back(timeout * 1e6);
      }
    }
    if (2 * problem_solved > seeds) ++solved;
    search_us.push_back(Median(search));
    plan_us.push_back(Median(plan));
    if (!tested.empty()) {
      checks.push_back(Median(tested));
      search_checks.push_back(Median(tested_searching));
    }
  }
  std::printf(
      "{\"problems\": %d, \"seeds\": %d, \"planner\": \"%s\", \"solved\": %d, \"search_us_p50\": %.1f, "
      "\"search_us_p95\": %.1f, \"plan_us_p50\": %.1f, \"plan_us_p95\": %.1f, \"checks_per_plan_p50\": %.0f, "
      "\"search_checks_per_plan_p50\": %.0f, \"checks_per_plan_p95\": %.0f, "
      "\"path_length_sum_rad\": %.4f, \"runs\": %d, \"plan_us_total_solved\": %.0f}\n",
      counted, seeds, PlannerName(planner), solved, Median(search_us), Percentile(search_us, 0.95), Median(plan_us),
      Percentile(plan_us, 0.95), Median(checks), Median(search_checks), Percentile(checks, 0.95), length_sum, runs,
      plan_total_us);
  return 0;
}

}  // namespace
}  // namespace graspsim::motion

int main(int argc, char** argv) { return graspsim::motion::Run(argc, argv); }
