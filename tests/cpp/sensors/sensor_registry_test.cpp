// The sensor registry on a scene of built-in robots: which sensor an id names (a PG70's pads, its gripper state,
// a joint's force/torque), the reading of each, and the errors for ids that name none.
#include "sensors/sensor_registry.h"

#include <cmath>
#include <string>
#include <variant>

#include <gtest/gtest.h>

#include "import/robot_import.h"
#include "test_util.h"
#include "world/loaders.h"
#include "world/scene.h"

namespace graspsim {
namespace {

using test_util::ExpectError;

// The PG70 (two pads, prismatic fingers) with its fingers 2 cm open each, and a Barrett hand (revolute joints
// only: no gripper state).
SceneView PgAndBarrett() {
  Scene scene("s", "s", Limits());
  auto load = [](const std::string& name) {
    return LoadUrdf(BuiltinModelUrdf(name), [](const std::string&) { return nullptr; }, Limits());
  };
  scene.AddRobot("pg70", "builtin:schunk_pg70", load("schunk_pg70"), Pose());
  scene.AddRobot("bh", "builtin:barrett_bh8_282", load("barrett_bh8_282"), Pose{Vec3(1, 0, 0), Quat::Identity()});
  scene.SetJointPositions({{"pg70/finger_left_joint", 0.02}});
  return scene.View();
}

TEST(SensorRegistryTest, PadsReadAsTactileFrames) {
  const SceneView view = PgAndBarrett();
  const SensorRef sensor = FindSensor(view, "sensor_id", "pg70/pad_left");
  EXPECT_EQ(sensor.kind, SensorRef::Kind::kTactile);
  EXPECT_EQ(sensor.index, view.model->tactile_index.at("pg70/pad_left"));

  const SensorReading reading = ReadSensor(view, sensor, "pg70/pad_left");
  EXPECT_EQ(reading.sensor_id, "pg70/pad_left");
  EXPECT_EQ(reading.time, view.state.time);
  ASSERT_TRUE(std::holds_alternative<TactileFrame>(reading.value));
  const TactileFrame& frame = std::get<TactileFrame>(reading.value);
  EXPECT_EQ(size_t{frame.rows} * frame.cols, 84u) << "a DSA 9205: 6 x 14 texels";
  EXPECT_EQ(frame.intensity_sum, 0u) << "a scene that never stepped touches nothing";
}

TEST(SensorRegistryTest, GripperStateOfARobotWithPrismaticFingers) {
  const SceneView view = PgAndBarrett();
  const SensorRef sensor = FindSensor(view, "sensor_id", "pg70/gripper");
  EXPECT_EQ(sensor.kind, SensorRef::Kind::kGripper);
  EXPECT_EQ(sensor.index, view.model->robot_index.at("pg70"));
  const SensorReading reading = ReadSensor(view, sensor, "pg70/gripper");
  ASSERT_TRUE(std::holds_alternative<GripperReading>(reading.value));
  EXPECT_NEAR(std::get<GripperReading>(reading.value).finger_distance, 0.04, 1e-12);
}

TEST(SensorRegistryTest, EveryJointOfARobotIsAForceTorqueSensor) {
  const SceneView view = PgAndBarrett();
  ASSERT_GT(view.model->joints.size(), 2u);
  for (size_t j = 0; j < view.model->joints.size(); ++j) {
    const SensorRef sensor = FindSensor(view, "sensor_id", view.model->joints[j].id);
    EXPECT_EQ(sensor.kind, SensorRef::Kind::kForceTorque) << view.model->joints[j].id;
    EXPECT_EQ(sensor.index, j) << view.model->joints[j].id;
  }
  const SensorRef finger = FindSensor(view, "sensor_id", "pg70/finger_left_joint");
  const SensorReading reading = ReadSensor(view, finger, "pg70/finger_left_joint");
  ASSERT_TRUE(std::holds_alternative<ForceTorqueReading>(reading.value));
  EXPECT_EQ(std::get<ForceTorqueReading>(reading.value).force, Vec3::Zero()) << "zero before the first step";
}

TEST(SensorRegistryTest, IdsThatNameNoSensorAreRefusedWithTheAvailableOnes) {
  const SceneView view = PgAndBarrett();
  ExpectError([&] { FindSensor(view, "sensor_ids[2]", ""); }, ErrorCode::kInvalidArgument,
              {"sensor_ids[2]: empty", "available: pg70/gripper, pg70/pad_left, pg70/pad_right"});
  ExpectError([&] { FindSensor(view, "sensor_id", "pg70/pad_middle"); }, ErrorCode::kNotFound,
              {"sensor_id: no sensor 'pg70/pad_middle' in scene 's'", "available:", " more"});
  ExpectError([&] { FindSensor(view, "sensor_id", "bh/gripper"); }, ErrorCode::kNotFound,
              {"robot 'bh' has no prismatic joints, so no gripper state"});
}

// The heat map is a PNG of the pad's texels at the scale asked (20 px per texel by default), and a scale that would
// make a side over 4096 px is refused naming the largest that fits.
TEST(SensorRegistryTest, TactileHeatMapsAreOfPadsOnlyAndOfBoundedSize) {
  const SceneView view = PgAndBarrett();
  const TactileHeatMap image = TactileHeatMapOf(view, "pg70/pad_left", 0);
  EXPECT_EQ(image.width * image.height, 84u * 20 * 20);
  ASSERT_GT(image.png.size(), 8u);
  EXPECT_EQ(image.png.substr(1, 3), "PNG");
  EXPECT_EQ(TactileHeatMapOf(view, "pg70/pad_left", 3).width * 20, image.width * 3);
  ExpectError([&] { TactileHeatMapOf(view, "pg70/pad_left", 1000); }, ErrorCode::kInvalidArgument,
              {"scale: 1000", "scale <= 292"});
  ExpectError([&] { TactileHeatMapOf(view, "pg70/gripper", 0); }, ErrorCode::kInvalidArgument,
              {"sensor_id", "not a tactile array"});
}

TEST(SensorRegistryTest, AStreamNeedsAPositiveRateWithinTheLimitAndDistinctIds) {
  CheckSensorStream(30, 60, {"pg70/pad_left", "pg70/pad_right"});
  ExpectError([] { CheckSensorStream(0, 60, {"a"}); }, ErrorCode::kInvalidArgument, {"rate_hz", "> 0"});
  ExpectError([] { CheckSensorStream(NAN, 60, {"a"}); }, ErrorCode::kInvalidArgument, {"rate_hz"});
  ExpectError([] { CheckSensorStream(61, 60, {"a"}); }, ErrorCode::kInvalidArgument, {"rate_hz", "limit of 60"});
  ExpectError([] { CheckSensorStream(30, 60, {}); }, ErrorCode::kInvalidArgument, {"sensor_ids: empty"});
  ExpectError([] { CheckSensorStream(30, 60, {"a", "b", "a"}); }, ErrorCode::kInvalidArgument,
              {"sensor_ids[2]", "listed twice"});
}

}  // namespace
}  // namespace graspsim
