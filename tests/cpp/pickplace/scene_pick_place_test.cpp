// PickAndPlace's job on a Scene without gRPC (pickplace/scene_pick_place.h): requests refused before any planning
// name their field; a named grasp set is looked up in the store and checked against the arm's hand and the
// object's mesh; the default set is planned (progress 0 … 0.2 as planning_grasps) and stored, and a successful run
// commits the object at the goal to the scene; a run during which the scene changed commits nothing; a cancel
// while planning the set leaves the scene as it was.
#include "pickplace/scene_pick_place.h"

#include <filesystem>
#include <random>

#include <gtest/gtest.h>

#include "cpp/motion/motion_test_scenes.h"
#include "test_bodies.h"
#include "test_util.h"

namespace graspsim {
namespace {

using motion_test::At;
using pickplace::PickAndPlaceInScene;
using pickplace::PickPlaceRequest;
using pickplace::Stage;
using test_util::ExpectError;

const Pose kGoal = At(0.05, -0.2, 0.775);

// The KR 5 with the PG70 at a table, a 5 cm cube on it and a static block beside it.
motion_test::ArmScene CubeScene() {
  return motion_test::MakeArmScene("kuka_kr5_sixx_r850_pg70", At(-0.45, 0, 0.75), [](Scene* scene) {
    motion_test::AddStatic(scene, "table", motion_test::BoxGeometry(Vec3(1.2, 0.8, 0.04)), At(0, 0, 0.73));
    scene->AddObject(test_objects::UniformBox("cube", Vec3::Constant(0.05), 0.1), At(0.05, 0.2, 0.775));
    scene->AddObject(test_objects::UniformBox("marker", Vec3::Constant(0.02), 0.05), At(0.3, 0.3, 0.76));
  });
}

PickPlaceRequest Request() {
  PickPlaceRequest r;
  r.arm_id = "arm";
  r.body_id = "cube";
  r.goal = kGoal;
  r.max_attempts = 3;
  return r;
}

TEST(ScenePickPlace, RefusalsBeforePlanningNameTheField) {
  const motion_test::ArmScene s = CubeScene();
  test_util::TempDir dir("pickplace-test");
  grasp::GraspStore store(dir.str());
  const auto refused = [&](auto change, grasp::GraspStore* with, ErrorCode code, std::initializer_list<const char*> parts) {
    PickPlaceRequest r = Request();
    change(r);
    ExpectError([&] { PickAndPlaceInScene(s.scene.get(), r, with, nullptr); }, code, parts);
  };
  const ErrorCode invalid = ErrorCode::kInvalidArgument;
  refused([](auto& r) { r.arm_id = ""; }, &store, invalid, {"arm_id: empty"});
  refused([](auto& r) { r.body_id = ""; }, &store, invalid, {"body_id: empty"});
  refused([](auto& r) { r.goal.reset(); }, &store, invalid, {"goal: absent"});
  refused([](auto& r) { r.max_attempts = 51; }, &store, invalid, {"max_attempts: 51 is above 50"});
  refused([](auto& r) { r.arm_id = "ghost"; }, &store, ErrorCode::kNotFound, {"arm_id", "'ghost'"});
  refused([](auto& r) { r.hand_id = "barrett_bh8_282"; }, &store, invalid,
          {"hand_id: 'barrett_bh8_282' is not on arm 'arm'", "carries 'schunk_pg70'"});
  refused([](auto& r) { r.hand_id = "claw"; }, &store, invalid, {"hand_id", "claw"});
  refused([](auto& r) { r.body_id = "ghost"; }, &store, ErrorCode::kNotFound, {"body_id: no body 'ghost' in scene 's'"});
  refused([](auto& r) { r.body_id = "table"; }, &store, invalid, {"body_id: 'table' is not a free body"});
  const std::string unknown(64, '0');
  refused([&](auto& r) { r.grasp_set_id = unknown; }, nullptr, ErrorCode::kFailedPrecondition,
          {"grasp_set_id: the server stores no grasp sets"});
  refused([&](auto& r) { r.grasp_set_id = unknown; }, &store, ErrorCode::kNotFound, {"grasp_set_id: no stored grasp set"});
  refused([](auto& r) { r.grasp_set_id = "abc"; }, &store, invalid, {"grasp_set_id: 'abc' is not a grasp-set id"});
  // Stored sets for another hand, or for another mesh than the body's.
  const std::string barrett(64, 'b'), other_mesh(64, 'c');
  store.Put({barrett, "barrett_bh8_282", "hash", "", 0, {}});
  store.Put({other_mesh, "schunk_pg70", "not the cube's mesh", "", 0, {}});
  refused([&](auto& r) { r.grasp_set_id = barrett; }, &store, invalid,
          {"grasp_set_id: set '" "bbbb", "is for hand 'barrett_bh8_282', arm 'arm' carries 'schunk_pg70'"});
  refused([&](auto& r) { r.grasp_set_id = other_mesh; }, &store, invalid, {"was planned for another mesh than body 'cube'"});
  EXPECT_EQ(s.scene->revision(), s.view.revision);
}

TEST(ScenePickPlace, ACancelWhilePlanningTheGraspSetChangesNothing) {
  const motion_test::ArmScene s = CubeScene();
  std::vector<Stage> stages;
  const pickplace::ScenePickPlaceResult r =
      PickAndPlaceInScene(s.scene.get(), Request(), nullptr, [&](Stage stage, double) {
        stages.push_back(stage);
        return false;
      });
  EXPECT_TRUE(r.cancelled);
  ASSERT_EQ(stages.size(), 1u);
  EXPECT_EQ(stages[0], Stage::kPlanGrasps);
  EXPECT_EQ(s.scene->revision(), s.view.revision);
}

// One planned run that commits, then the stored set named again in a run during which the scene changes.
TEST(ScenePickPlace, ASuccessfulRunCommitsUnlessTheSceneChangedMeanwhile) {
  const motion_test::ArmScene s = CubeScene();
  test_util::TempDir dir("pickplace-test");
  grasp::GraspStore store(dir.str());
  double last_fraction = 0, planning_until = 0;
  bool monotonic = true;
  const pickplace::ScenePickPlaceResult planned =
      PickAndPlaceInScene(s.scene.get(), Request(), &store, [&](Stage stage, double fraction) {
        monotonic = monotonic && fraction >= last_fraction - 1e-12;
        last_fraction = fraction;
        if (stage == Stage::kPlanGrasps) planning_until = fraction;
        return true;
      });
  ASSERT_FALSE(planned.cancelled);
  EXPECT_TRUE(planned.run.success);
  EXPECT_TRUE(planned.set_planned);
  EXPECT_TRUE(monotonic);
  EXPECT_GT(planning_until, 0);
  EXPECT_LE(planning_until, 0.2 + 1e-12);
  ASSERT_TRUE(store.Find(planned.set.key));  // stored for the next request
  const SceneView after = s.scene->View();
  EXPECT_GT(after.revision, s.view.revision);
  const Pose cube = after.state.body_poses[after.model->body_index.at("cube")];
  EXPECT_LT((cube.position - kGoal.position).norm(), 0.01);  // the scene holds the simulated end

  // The set by its id in the same scene anew: no planning; the marker moved while the job runs, so its result is
  // not committed.
  const motion_test::ArmScene again = CubeScene();
  PickPlaceRequest named = Request();
  named.grasp_set_id = planned.set.key;
  bool moved = false;
  ExpectError([&] {
    PickAndPlaceInScene(again.scene.get(), named, &store, [&](Stage stage, double) {
      EXPECT_NE(stage, Stage::kPlanGrasps);
      if (!moved && stage == Stage::kApproach) {
        again.scene->SetBodyPoses({{"marker", At(0.3, 0.32, 0.76)}});
        moved = true;
      }
      return true;
    });
  }, ErrorCode::kFailedPrecondition, {"the scene changed during the pick-and-place; its result was not committed"});
  EXPECT_TRUE(moved);
  const SceneView unchanged = again.scene->View();
  EXPECT_EQ(unchanged.state.body_poses[unchanged.model->body_index.at("cube")].position, At(0.05, 0.2, 0.775).position);
}

}  // namespace
}  // namespace graspsim
