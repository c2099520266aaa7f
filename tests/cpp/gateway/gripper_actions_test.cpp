// One controller, simulated and real: the work cycle's gripper actions (approach, grasp, release) run unchanged
// on the simulated PG70 (a 5 cm box between its fingers) and, through the drivers, on the emulated PG70 and
// Robotiq 2F-85 (a 5 cm object).
#include "gateway/gripper_actions.h"

#include <sys/socket.h>

#include <chrono>
#include <thread>

#include <gtest/gtest.h>

#include "drivers/emulators/pg70_emulator.h"
#include "drivers/emulators/robotiq_emulator.h"
#include "drivers/pg70/pg70_gripper.h"
#include "drivers/robotiq/robotiq_gripper.h"
#include "gateway/simulated_gripper.h"
#include "test_bodies.h"
#include "import/robot_import.h"
#include "world/loaders.h"
#include "world/scene.h"

namespace graspsim::gateway {
namespace {

constexpr double kWidth = 0.05;  // m, the object between the fingers
const auto kActions = GraspActions(kWidth, 0.04, 100);

void Sleep() { std::this_thread::sleep_for(std::chrono::milliseconds(10)); }

TEST(GripperActions, RunOnTheSimulatedPg70) {
  Scene scene("s", "test", Limits{});
  scene.AddRobot("pg", "builtin:schunk_pg70",
                 LoadUrdf(BuiltinModelUrdf("schunk_pg70"), [](const std::string&) { return nullptr; }, Limits()),
                 Pose());
  // A static 5 cm box where the pads meet it: 0.135 m along the gripper's approach axis (the demo's grasp).
  scene.AddObject(test_objects::UniformBox("box", Vec3::Constant(kWidth), 0.2, BodyMotion::kStatic),
                  {Vec3(0, 0, 0.135), Quat::Identity()});
  SceneView view = scene.View();
  SimulatedGripper twin(view.model, view.state, "pg");
  twin.SetOpening(0.030 + 0.040);  // start wide open
  auto step = [&] { twin.AdvanceTo(twin.time() + 0.01); };

  const auto approach = RunAction(twin, kActions[0], step, 500);
  EXPECT_NEAR(approach.opening_m, kWidth + 0.02, 5e-4);
  EXPECT_FALSE(approach.object_detected);
  const auto grasp = RunAction(twin, kActions[1], step, 500);
  // Stopped on the box: the pads' 4 mm foam compresses a little under 100 N, the fingers go no further.
  EXPECT_GT(grasp.opening_m, kWidth - 0.008);
  EXPECT_LT(grasp.opening_m, kWidth + 0.001);
  EXPECT_TRUE(grasp.object_detected);
  EXPECT_GT(twin.TactileSum(), 0);
  EXPECT_GT(grasp.current_a, 1.0);  // holding: about 100 N / 57 N/A
  const auto release = RunAction(twin, kActions[2], step, 500);
  EXPECT_NEAR(release.opening_m, kWidth + 0.02, 5e-4);
  EXPECT_EQ(twin.TactileSum(), 0);
}

TEST(GripperActions, RunOnTheEmulatedPg70AndRobotiq) {
  int fds[2];
  ASSERT_EQ(socketpair(AF_UNIX, SOCK_SEQPACKET, 0, fds), 0);
  drivers::emulators::Pg70Emulator::Options pg70_options;
  pg70_options.object_width_mm = kWidth * 1000;
  drivers::emulators::Pg70Emulator pg70_emulator(fds[1], pg70_options);
  auto pg70 = drivers::MakeGripperDevice(std::make_unique<drivers::pg70::Gripper>(
      std::make_unique<drivers::can::CanTransport>(fds[0], "socketpair"), drivers::pg70::Config{}));
  drivers::emulators::RobotiqModel::Options robotiq_options;
  robotiq_options.object_opening_mm = kWidth * 1000;
  auto robotiq_emulator = drivers::emulators::RobotiqEmulator::StartTcp(robotiq_options);
  drivers::modbus::TcpEndpoint endpoint;
  endpoint.port = robotiq_emulator->port();
  auto robotiq = drivers::MakeGripperDevice(
      std::make_unique<drivers::robotiq::Gripper>(drivers::modbus::ConnectTcp(endpoint), drivers::robotiq::Config{}));

  for (drivers::GripperDevice* device : {pg70.get(), robotiq.get()}) {
    SCOPED_TRACE(device->Name());
    device->Initialize();
    const double resolution = 1e-3;  // a Robotiq position count is 0.33 mm
    EXPECT_NEAR(RunAction(*device, kActions[0], Sleep, 1000).opening_m, kWidth + 0.02, resolution);
    const auto grasp = RunAction(*device, kActions[1], Sleep, 1000);
    EXPECT_NEAR(grasp.opening_m, kWidth, resolution);
    EXPECT_TRUE(grasp.object_detected);
    const auto release = RunAction(*device, kActions[2], Sleep, 1000);
    EXPECT_NEAR(release.opening_m, kWidth + 0.02, resolution);
    EXPECT_FALSE(release.object_detected);
  }
}

}  // namespace
}  // namespace graspsim::gateway
