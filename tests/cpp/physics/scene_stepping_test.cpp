// StepSimulation's and SetActuators' logic on a Scene, without gRPC (physics/scene_stepping.h): how many steps an
// amount is and the refusals naming the field; a run committed chunk by chunk, stopped by its cancel callback, and
// checkpointed at its end and when the simulation diverges (a fake journal sees the stored states); actuator
// settings validated against the model and applied all or nothing, with the built-in drive as the default motor.
#include "physics/scene_stepping.h"

#include <cmath>
#include <vector>

#include <gtest/gtest.h>

#include "import/robot_import.h"
#include "physics/builtin_drives.h"
#include "test_bodies.h"
#include "test_util.h"
#include "world/loaders.h"

namespace graspsim {
namespace {

using test_util::ExpectError;

// A 5 cm box 1 m up in free fall, steps of 1 ms (17 a chunk).
std::unique_ptr<Scene> FallingBox() {
  auto scene = std::make_unique<Scene>("s", "stepping", Limits());
  scene->AddObject(test_objects::UniformBox("box", Vec3::Constant(0.05), 0.1), {Vec3(0, 0, 1), Quat::Identity()});
  SimulationParams params = scene->View().model->simulation;
  params.time_step = 1e-3;
  scene->SetSimulationParams(params);
  return scene;
}

TEST(SceneStepping, AnAmountIsStepsOrTimeAndIsRefusedNamingItsField) {
  EXPECT_EQ(StepsFor(StepAmount::Steps(7), 0, 1e-3), 7u);
  EXPECT_EQ(StepsFor(StepAmount::Duration(0.25), 3, 1e-3), 250u);
  EXPECT_EQ(StepsFor(StepAmount::UntilTime(1.5), 1.0, 1e-2), 50u);
  EXPECT_EQ(StepsFor(StepAmount::UntilTime(1.0), 1.0, 1e-2), 0u);  // already there
  ExpectError([] { StepsFor({}, 0, 1e-3); }, ErrorCode::kInvalidArgument, {"amount: give steps, duration or until_time"});
  ExpectError([] { StepsFor(StepAmount::Duration(-1), 0, 1e-3); }, ErrorCode::kInvalidArgument, {"duration"});
  ExpectError([] { StepsFor(StepAmount::UntilTime(NAN), 0, 1e-3); }, ErrorCode::kInvalidArgument, {"until_time"});
  ExpectError([] { StepsFor(StepAmount::UntilTime(0.5), 2, 1e-3); }, ErrorCode::kInvalidArgument,
              {"until_time: 0.5 s is before the scene's time 2 s"});
  ExpectError([] { StepsFor(StepAmount::Steps(kMaxStepsPerRun + 1), 0, 1e-3); }, ErrorCode::kInvalidArgument,
              {"amount: 100000001 steps", "at most 100000000"});
  ExpectError([] { StepsFor(StepAmount::Duration(1e9), 0, 1e-3); }, ErrorCode::kInvalidArgument, {"amount:"});
}

TEST(SceneStepping, ARunCommitsEveryChunkAndStoresTheStateOnceAtTheEnd) {
  auto scene = FallingBox();
  test_util::CheckpointJournal journal;
  scene->AttachJournal(&journal);
  SimulationCache simulations;
  const uint64_t before = scene->revision();
  const StepRunResult r = StepScene(scene.get(), &simulations, StepAmount::Duration(0.05), nullptr);
  EXPECT_EQ(r.steps, 50u);
  EXPECT_NEAR(r.time, 0.05, 1e-12);
  EXPECT_EQ(r.revision, scene->revision());
  EXPECT_EQ(r.revision - before, 3u);  // 17 + 17 + 16 steps, each chunk a commit the watchers see
  EXPECT_EQ(r.awake_bodies, 1u);
  // Fallen g t² / 2 in 50 ms: the run stepped the scene itself.
  EXPECT_NEAR(scene->View().state.body_poses[0].position.z(), 1 - 9.81 * 0.05 * 0.05 / 2, 1e-3);
  ASSERT_EQ(journal.checkpoint_times.size(), 1u);  // not per chunk
  EXPECT_NEAR(journal.checkpoint_times[0], 0.05, 1e-12);
}

TEST(SceneStepping, ACancelStopsTheRunBetweenChunks) {
  auto scene = FallingBox();
  SimulationCache simulations;
  int asked = 0;
  const StepRunResult r =
      StepScene(scene.get(), &simulations, StepAmount::Steps(1000), [&] { return ++asked > 2; });
  EXPECT_EQ(r.steps, 2 * StepsPerChunk(scene->View().model->simulation));
  EXPECT_EQ(asked, 3);
  EXPECT_NEAR(scene->View().state.time, r.time, 0);
}

TEST(SceneStepping, ADivergedRunStoresWhatItCommittedBeforeTheError) {
  auto scene = FallingBox();
  SimulationParams params = scene->View().model->simulation;
  params.divergence_speed = 1;  // m/s: reached after ~0.1 s of falling
  scene->SetSimulationParams(params);
  test_util::CheckpointJournal journal;
  scene->AttachJournal(&journal);
  SimulationCache simulations;
  ExpectError([&] { StepScene(scene.get(), &simulations, StepAmount::Duration(1), nullptr); },
              ErrorCode::kFailedPrecondition, {"diverged", "'box'"});
  const double time = scene->View().state.time;
  EXPECT_GT(time, 0.05);   // the chunks before the failing one stay committed …
  EXPECT_LT(time, 0.2);
  ASSERT_EQ(journal.checkpoint_times.size(), 1u);  // … and stored
  EXPECT_EQ(journal.checkpoint_times[0], time);
}

// The PG70 on its z axis: z_axis and finger_left_joint are driven, finger_right_joint mimics the left finger,
// carriage_to_gripper is fixed.
std::unique_ptr<Scene> Cell() {
  auto scene = std::make_unique<Scene>("s", "actuators", Limits());
  scene->AddRobot("cell", "builtin:schunk_pg70_on_z_axis",
                  LoadUrdf(BuiltinModelUrdf("schunk_pg70_on_z_axis"), nullptr, Limits()), {Vec3(0, 0, 1), Quat::Identity()});
  return scene;
}

ActuatorSetting Setting(const std::string& joint, ActuatorMode mode, double value = 0) {
  ActuatorSetting s;
  s.joint_id = joint;
  s.command.mode = mode;
  s.command.value = value;
  return s;
}

size_t JointIndex(const Scene& scene, const std::string& id) { return scene.View().model->joint_index.at(id); }

TEST(SceneActuators, AJointWithoutAMotorGetsItsRobotsDriveAndOffRemovesIt) {
  auto scene = Cell();
  DcMotorParams own;
  own.ratio = 42;
  ActuatorSetting axis = Setting("cell/z_axis", ActuatorMode::kPosition, 0.1);
  axis.motor = own;
  SetSceneActuators(scene.get(), {Setting("cell/finger_left_joint", ActuatorMode::kVelocity, -0.01), axis});
  const SceneView view = scene->View();
  const size_t finger = JointIndex(*scene, "cell/finger_left_joint"), z = JointIndex(*scene, "cell/z_axis");
  ASSERT_EQ(view.state.actuators.size(), 2u);
  const RobotSpec& robot = view.model->robots[0];
  EXPECT_EQ(view.state.actuators.at(finger).motor.ratio, BuiltinDrive(robot, view.model->joints[finger]).ratio);
  EXPECT_EQ(view.state.actuators.at(finger).command.mode, ActuatorMode::kVelocity);
  EXPECT_EQ(view.state.actuators.at(z).motor.ratio, 42);
  EXPECT_EQ(view.state.actuators.at(z).command.value, 0.1);
  SetSceneActuators(scene.get(), {Setting("cell/z_axis", ActuatorMode::kOff)});
  EXPECT_EQ(scene->View().state.actuators.count(z), 0u);
  EXPECT_EQ(scene->View().state.actuators.count(finger), 1u);
}

TEST(SceneActuators, RefusalsNameTheCommandAndChangeNothing) {
  auto scene = Cell();
  const auto refused = [&](const std::string& joint, ErrorCode code, std::initializer_list<const char*> parts) {
    const uint64_t revision = scene->revision();
    ExpectError([&] {
      SetSceneActuators(scene.get(), {Setting("cell/z_axis", ActuatorMode::kPosition, 0.1),
                                      Setting(joint, ActuatorMode::kVelocity, 1)});
    }, code, parts);
    EXPECT_TRUE(scene->View().state.actuators.empty());  // the valid first command was not applied either
    EXPECT_EQ(scene->revision(), revision);
  };
  refused("cell/nope", ErrorCode::kNotFound, {"commands[1].joint_id: no joint 'cell/nope' in scene 's'"});
  refused("cell/finger_right_joint", ErrorCode::kInvalidArgument,
          {"commands[1].joint_id: 'cell/finger_right_joint' is a mimic joint; drive its leader"});
  refused("cell/carriage_to_gripper", ErrorCode::kInvalidArgument,
          {"commands[1].joint_id: 'cell/carriage_to_gripper' is a fixed joint"});
}

}  // namespace
}  // namespace graspsim
