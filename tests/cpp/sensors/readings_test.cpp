// The PG70's gripper state read from a hand-set state of the built-in gripper.
#include "sensors/readings.h"

#include <gtest/gtest.h>

#include "import/robot_import.h"
#include "world/loaders.h"
#include "world/scene.h"

namespace graspsim {
namespace {

TEST(ReadingsTest, Pg70GripperState) {
  Scene scene("s", "s", Limits());
  const RobotDescription pg70 =
      LoadUrdf(BuiltinModelUrdf("schunk_pg70"), [](const std::string&) { return nullptr; }, Limits());
  scene.AddRobot("pg70", "builtin:schunk_pg70", pg70, Pose());
  scene.SetJointPositions({{"pg70/finger_left_joint", 0.02}});
  SceneView view = scene.View();
  const SceneModel& model = *view.model;
  const RobotSpec& robot = model.robots[model.robot_index.at("pg70")];

  GripperReading reading = ReadGripper(model, view.state, robot);
  EXPECT_NEAR(reading.finger_distance, 0.04, 1e-12) << "both fingers: the mimic follows the driven one";
  EXPECT_EQ(reading.motor_current, 0) << "undriven";

  const size_t left = model.joint_index.at("pg70/finger_left_joint");
  const size_t right = model.joint_index.at("pg70/finger_right_joint");
  view.state.joint_velocities.assign(model.joints.size(), 0.0);
  view.state.joint_velocities[left] = -0.02;
  view.state.joint_velocities[right] = -0.02;
  view.state.actuators[left].state.current = 1.25;
  reading = ReadGripper(model, view.state, robot);
  EXPECT_DOUBLE_EQ(reading.finger_velocity, -0.02);
  EXPECT_DOUBLE_EQ(reading.motor_current, 1.25);
}

}  // namespace
}  // namespace graspsim
