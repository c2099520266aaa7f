// One controller, every gripper: the same open / close-on-object / release / stop sequence in SI units runs
// against the Robotiq 2F-85 (Modbus TCP and RTU) and the PG70 (SMP over a CAN socketpair) through GripperDevice.
#include "drivers/device/gripper_device.h"

#include <sys/socket.h>

#include <chrono>
#include <thread>

#include <gtest/gtest.h>

#include "drivers/emulators/pg70_emulator.h"
#include "drivers/emulators/robotiq_emulator.h"
#include "drivers/pg70/pg70_gripper.h"
#include "drivers/robotiq/robotiq_gripper.h"
#include "test_util.h"

namespace graspsim::drivers {
namespace {

enum class Kind { kRobotiqTcp, kRobotiqRtu, kPg70 };
void PrintTo(Kind kind, std::ostream* out) {
  *out << (kind == Kind::kRobotiqTcp ? "robotiq tcp" : kind == Kind::kRobotiqRtu ? "robotiq rtu" : "pg70 can");
}

constexpr double kObjectMm = 30.0;

struct Bench {
  std::unique_ptr<emulators::RobotiqEmulator> robotiq;
  std::unique_ptr<emulators::Pg70Emulator> pg70;
  std::unique_ptr<GripperDevice> device;
  double tolerance_m = 0.0;  // the device's position resolution
};

Bench MakeBench(Kind kind) {
  Bench bench;
  const modbus::LinkTimeouts timeouts{std::chrono::milliseconds(500), std::chrono::milliseconds(100)};
  if (kind == Kind::kPg70) {
    int fds[2];
    if (socketpair(AF_UNIX, SOCK_SEQPACKET, 0, fds) != 0) throw std::runtime_error("socketpair");
    emulators::Pg70Emulator::Options options;
    options.object_width_mm = kObjectMm;
    bench.pg70 = std::make_unique<emulators::Pg70Emulator>(fds[1], options);
    pg70::Config config;
    config.timeout = timeouts.response;
    bench.device = MakeGripperDevice(
        std::make_unique<pg70::Gripper>(std::make_unique<can::CanTransport>(fds[0], "socketpair"), config));
    bench.tolerance_m = 1e-6;
    return bench;
  }
  emulators::RobotiqModel::Options options;
  options.object_opening_mm = kObjectMm;
  std::unique_ptr<modbus::ModbusTransport> link;
  if (kind == Kind::kRobotiqTcp) {
    bench.robotiq = emulators::RobotiqEmulator::StartTcp(options);
    modbus::TcpEndpoint endpoint;
    endpoint.port = bench.robotiq->port();
    endpoint.timeouts = timeouts;
    link = modbus::ConnectTcp(endpoint);
  } else {
    bench.robotiq = emulators::RobotiqEmulator::StartRtu(options);
    modbus::RtuEndpoint endpoint;
    endpoint.device = bench.robotiq->device();
    endpoint.timeouts = timeouts;
    link = modbus::ConnectRtu(endpoint);
  }
  bench.device = MakeGripperDevice(std::make_unique<robotiq::Gripper>(std::move(link), robotiq::Config{}));
  bench.tolerance_m = 85.0 / 255 / 1000;  // one position count
  return bench;
}

GripperReading WaitUntilStopped(GripperDevice& device) {
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(10);
  GripperReading r = device.Read();
  while (r.moving && std::chrono::steady_clock::now() < deadline) {
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
    r = device.Read();
  }
  return r;
}

class GripperDeviceTest : public ::testing::TestWithParam<Kind> {};

TEST_P(GripperDeviceTest, OpenGraspReleaseStopWithOneController) {
  Bench bench = MakeBench(GetParam());
  GripperDevice& gripper = *bench.device;
  EXPECT_FALSE(gripper.Name().empty());
  gripper.Initialize();

  gripper.MoveTo(0.05, 0.05, 60.0);  // pre-shape: 50 mm open
  GripperReading r = WaitUntilStopped(gripper);
  EXPECT_FALSE(r.moving);
  EXPECT_NEAR(r.opening_m, 0.05, bench.tolerance_m);
  EXPECT_FALSE(r.object_detected);
  EXPECT_TRUE(r.fault.empty()) << r.fault;

  gripper.MoveTo(0.0, 0.05, 60.0);  // grasp: closes on the 30 mm object
  r = WaitUntilStopped(gripper);
  EXPECT_TRUE(r.object_detected);
  EXPECT_NEAR(r.opening_m, kObjectMm / 1000, bench.tolerance_m);
  EXPECT_GT(r.current_a, 0.0);

  gripper.MoveTo(0.065, 0.05, 60.0);  // release
  r = WaitUntilStopped(gripper);
  EXPECT_FALSE(r.object_detected);
  EXPECT_NEAR(r.opening_m, 0.065, bench.tolerance_m);

  gripper.MoveTo(0.0, 0.02, 60.0);  // slow close, interrupted
  gripper.Stop();
  r = gripper.Read();
  EXPECT_FALSE(r.moving);
  EXPECT_GT(r.opening_m, kObjectMm / 1000);
}

TEST_P(GripperDeviceTest, LimitsOfTheDriverApply) {
  Bench bench = MakeBench(GetParam());
  bench.device->Initialize();
  test_util::ExpectError([&] { bench.device->MoveTo(0.2, 0.05, 60.0); }, ErrorCode::kInvalidArgument, {"200"});
  test_util::ExpectError([&] { bench.device->MoveTo(0.03, 0.5, 60.0); }, ErrorCode::kInvalidArgument, {"500"});
  test_util::ExpectError([&] { bench.device->MoveTo(0.03, 0.05, 1000.0); }, ErrorCode::kInvalidArgument, {"outside"});
}

INSTANTIATE_TEST_SUITE_P(GripperDevices, GripperDeviceTest,
                         ::testing::Values(Kind::kRobotiqTcp, Kind::kRobotiqRtu, Kind::kPg70), [](const auto& info) {
                           return info.param == Kind::kRobotiqTcp   ? "RobotiqTcp"
                                  : info.param == Kind::kRobotiqRtu ? "RobotiqRtu"
                                                                    : "Pg70";
                         });

}  // namespace
}  // namespace graspsim::drivers
