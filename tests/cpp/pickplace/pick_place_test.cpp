// Pick and place (server/src/pickplace): a KR 5 with the PG70 moves a 5 cm cube across a table in the dynamic
// simulation. Checked independently of the library's own verdict: the object's simulated pose against the goal
// (1 cm, 10°), every executed arm motion re-checked with the exact geometry (motion/exact_checker.h) at ≤ 1 mm
// of tip travel and within the joint limits; an unreachable goal is FAILED_PRECONDITION naming why.
#include "pickplace/pick_place.h"

#include <cmath>
#include <optional>
#include <tuple>
#include <utility>

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

// Planned once for the suite (the cube's start pose is the same in every test).
const grasp::GraspSet& PlanSet(const SceneView& view) {
  static const grasp::GraspSet set = [&] {
  const grasp::PlanJob job = pickplace::DefaultGraspSetJob(*view.model, view.state, "arm", "cube", 1);
  const grasp::GraspPlanner planner(job.hand, job.mesh, job.obstacles, job.simulation);
  std::optional<grasp::GraspSet> planned =
      planner.Plan(planner.Candidates(job.candidates), 0, job.max_grasps, [](size_t, size_t) { return true; });
  return *planned;
  }();
  return set;
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
      const int n = std::max(1, static_cast<int>(std::ceil(travel / 0.001)));
      for (int j = 0; j <= n; ++j) {
        const motion::VecX q = w[i] + (w[i + 1] - w[i]) * (static_cast<double>(j) / n);
        ASSERT_TRUE(tip_arm.WithinLimits(q, 1e-9)) << "motion " << k;
        ASSERT_EQ(exact.Explain(q), "") << "motion " << k << " waypoint " << i << " step " << j;
      }
    }
  }
}

// Far out of reach (2 m from the base): FAILED_PRECONDITION naming why, with every grasp unreachable.
TEST(PickPlace, UnreachableGoalIsFailedPreconditionWithTheReason) {
  const motion_test::ArmScene s = CubeScene();
  try {
    RunOn(s.view, PlanSet(s.view), At(1.6, 0, 0.775));
    FAIL() << "no error";
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::kFailedPrecondition);
    const std::string what = e.what();
    EXPECT_NE(what.find("is reachable"), std::string::npos) << what;
    EXPECT_NE(what.find("unreachable: above the goal"), std::string::npos) << what;
  }
}

TEST(PickPlace, BadInputIsNamed) {
  const motion_test::ArmScene s = CubeScene();
  const grasp::GraspSet& set = PlanSet(s.view);
  const auto code_and_text = [&](const std::string& arm, const std::string& body, const Pose& goal) {
    try {
      pickplace::RunPickPlace(s.view.model, s.view.state, arm, body, goal, set, {}, nullptr);
    } catch (const Error& e) {
      return std::make_pair(e.code(), std::string(e.what()));
    }
    return std::make_pair(ErrorCode::kInternal, std::string("no error"));
  };
  auto [code, text] = code_and_text("nope", "cube", kCubeStart);
  EXPECT_EQ(code, ErrorCode::kNotFound);
  EXPECT_NE(text.find("arm_id: no robot 'nope'"), std::string::npos) << text;
  std::tie(code, text) = code_and_text("arm", "ghost", kCubeStart);
  EXPECT_EQ(code, ErrorCode::kNotFound);
  EXPECT_NE(text.find("body_id: no body 'ghost'"), std::string::npos) << text;
  std::tie(code, text) = code_and_text("arm", "table", kCubeStart);
  EXPECT_EQ(code, ErrorCode::kInvalidArgument);
  EXPECT_NE(text.find("'table' is not a free body"), std::string::npos) << text;
  std::tie(code, text) = code_and_text("arm", "cube", At(std::nan(""), 0, 0.8));
  EXPECT_EQ(code, ErrorCode::kInvalidArgument);
  EXPECT_NE(text.find("goal.position"), std::string::npos) << text;
  // A set for another hand.
  grasp::GraspSet barrett = set;
  barrett.hand = "barrett_bh8_282";
  try {
    pickplace::RunPickPlace(s.view.model, s.view.state, "arm", "cube", kCubeStart, barrett, {}, nullptr);
    ADD_FAILURE() << "no error";
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::kInvalidArgument);
    EXPECT_NE(std::string(e.what()).find("carries 'schunk_pg70'"), std::string::npos) << e.what();
  }
}

// A robot without a flange is not an arm; an arm without a hand carries none.
TEST(PickPlace, HandOnArmNamesWhatIsMissing) {
  const motion_test::ArmScene s = CubeScene();
  EXPECT_EQ(pickplace::HandOnArm(*s.view.model, "arm_id", "arm"), "schunk_pg70");
  const motion_test::ArmScene bare = motion_test::MakeArmScene("kuka_kr5_sixx_r850");
  try {
    pickplace::HandOnArm(*bare.view.model, "arm_id", "arm");
    ADD_FAILURE() << "no error";
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::kInvalidArgument);
    EXPECT_NE(std::string(e.what()).find("carries no known hand"), std::string::npos) << e.what();
  }
  const motion_test::ArmScene gripper = motion_test::MakeArmScene("schunk_pg70");
  try {
    pickplace::HandOnArm(*gripper.view.model, "arm_id", "arm");
    ADD_FAILURE() << "no error";
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::kInvalidArgument);
    EXPECT_NE(std::string(e.what()).find("is not an arm"), std::string::npos) << e.what();
  }
}

// Cancelling in the middle of the execution returns at once: no further stage is reported.
TEST(PickPlace, CancelStopsTheRun) {
  const motion_test::ArmScene s = CubeScene();
  int calls_after_cancel = 0;
  bool cancel = false;
  const pickplace::PickPlaceResult r =
      RunOn(s.view, PlanSet(s.view), At(0.05, -0.2, 0.775),
            [&](pickplace::Stage stage, double, const pickplace::PickPlaceResult&) {
              if (cancel) ++calls_after_cancel;
              if (stage == pickplace::Stage::kClose) cancel = true;
              return !cancel;
            });
  EXPECT_TRUE(r.cancelled);
  EXPECT_FALSE(r.success);
  EXPECT_EQ(calls_after_cancel, 0);
  EXPECT_LT(r.simulated_seconds, 8.0);  // the full run simulates ~8 s
}

}  // namespace
}  // namespace graspsim
