// Robotiq 2F-85 driver against the emulator on both real links: Modbus TCP on loopback and Modbus RTU over a
// pseudo-terminal pair (libmodbus on both ends). Every command and status path, limits, Modbus exceptions,
// malformed answers and timeouts; after every link failure the emulated gripper must be stopped (rGTO = 0).
#include "drivers/robotiq/robotiq_gripper.h"

#include <cmath>
#include <memory>
#include <string>

#include <gtest/gtest.h>

#include "drivers/emulators/robotiq_emulator.h"
#include "test_util.h"

namespace graspsim::drivers::robotiq {
namespace {

using emulators::ReplyFault;
using emulators::RobotiqEmulator;
using test_util::ExpectError;

enum class Link { kTcp, kRtu };
void PrintTo(Link link, std::ostream* out) { *out << (link == Link::kTcp ? "modbus tcp" : "modbus rtu"); }
constexpr std::chrono::milliseconds kSettle{10000};  // generous bound for a move the emulator does in < 1 s
constexpr double kCountMm = 85.0 / 255;               // one position count

std::unique_ptr<modbus::ModbusTransport> Connect(Link link, const RobotiqEmulator& emulator,
                                                 modbus::LinkTimeouts timeouts = {}) {
  if (link == Link::kTcp) {
    modbus::TcpEndpoint endpoint;
    endpoint.port = emulator.port();
    endpoint.timeouts = timeouts;
    return modbus::ConnectTcp(endpoint);
  }
  modbus::RtuEndpoint endpoint;
  endpoint.device = emulator.device();
  endpoint.timeouts = timeouts;
  return modbus::ConnectRtu(endpoint);
}

emulators::RobotiqModel::Options WithObject(double opening_mm) {
  emulators::RobotiqModel::Options options;
  options.object_opening_mm = opening_mm;
  return options;
}

struct Rig {
  std::unique_ptr<RobotiqEmulator> emulator;
  std::unique_ptr<Gripper> gripper;
};

Rig MakeRig(Link link, emulators::RobotiqModel::Options options = {}, Limits limits = {}) {
  Rig rig;
  // Long enough that a loaded 2-core machine never times out a healthy emulator; the timeout tests wait it out.
  const modbus::LinkTimeouts timeouts{std::chrono::milliseconds(500), std::chrono::milliseconds(100)};
  rig.emulator = link == Link::kTcp ? RobotiqEmulator::StartTcp(options) : RobotiqEmulator::StartRtu(options);
  Config config;
  config.limits = limits;
  rig.gripper = std::make_unique<Gripper>(Connect(link, *rig.emulator, timeouts), config);
  return rig;
}

// Expects a DeviceError of `failure` whose message contains every part; returns the message.
template <typename Fn>
std::string ExpectDeviceError(Fn&& fn, DeviceFailure failure, std::initializer_list<const char*> parts) {
  try {
    fn();
  } catch (const DeviceError& error) {
    EXPECT_EQ(error.failure(), failure) << error.what();
    for (const char* part : parts) EXPECT_NE(std::string(error.what()).find(part), std::string::npos) << error.what();
    return error.what();
  }
  ADD_FAILURE() << "no DeviceError thrown";
  return {};
}

class RobotiqGripperTest : public ::testing::TestWithParam<Link> {};

TEST_P(RobotiqGripperTest, ActivatesMovesAndReportsStatus) {
  Rig rig = MakeRig(GetParam());
  EXPECT_FALSE(rig.gripper->ReadStatus().activated);
  rig.gripper->Activate();
  Reading r = rig.gripper->ReadStatus();
  EXPECT_TRUE(r.activated);
  EXPECT_EQ(r.fault, kFaultNone);
  EXPECT_NEAR(r.opening_mm, 85.0, kCountMm);

  rig.gripper->Move(40.0, 150.0, 100.0);
  EXPECT_TRUE(rig.emulator->command().rGTO);
  r = rig.gripper->WaitUntilStopped(kSettle);
  EXPECT_NEAR(r.opening_mm, 40.0, kCountMm);
  EXPECT_NEAR(r.requested_opening_mm, 40.0, kCountMm);
  EXPECT_EQ(r.raw.gOBJ, ObjectState::kAtRequest);
  EXPECT_FALSE(r.object_detected);
  EXPECT_EQ(r.current_ma, 0.0);
  EXPECT_EQ(rig.emulator->command().rPR, PositionCounts(Calibration{}, 40.0));

  rig.gripper->Move(85.0, 20.0, 20.0);  // open again at the slowest speed and force
  EXPECT_EQ(rig.emulator->command().rSP, 0);
  EXPECT_EQ(rig.emulator->command().rFR, 0);
  EXPECT_NEAR(rig.gripper->WaitUntilStopped(kSettle).opening_mm, 85.0, kCountMm);
}

TEST_P(RobotiqGripperTest, ClosingOnAnObjectDetectsItAndDrawsCurrent) {
  Rig rig = MakeRig(GetParam(), WithObject(30.0));
  rig.gripper->Activate();
  rig.gripper->Move(0.0, 150.0, 235.0);
  const Reading r = rig.gripper->WaitUntilStopped(kSettle);
  EXPECT_TRUE(r.object_detected);
  EXPECT_EQ(r.raw.gOBJ, ObjectState::kContactClosing);
  EXPECT_NEAR(r.opening_mm, 30.0, kCountMm);
  EXPECT_NEAR(r.requested_opening_mm, 0.0, kCountMm);
  EXPECT_EQ(r.current_ma, 600.0);  // full force: the emulator's 0.6 A holding current
}

TEST_P(RobotiqGripperTest, StopHaltsTheFingersWhereTheyAre) {
  Rig rig = MakeRig(GetParam());
  rig.gripper->Activate();
  rig.gripper->Move(0.0, 20.0, 50.0);  // 85 mm at 20 mm/s: still moving when the stop arrives
  rig.gripper->Stop();
  EXPECT_FALSE(rig.emulator->command().rGTO);
  EXPECT_FALSE(rig.emulator->moving());
  const Reading r = rig.gripper->ReadStatus();
  EXPECT_FALSE(r.moving);
  EXPECT_FALSE(r.raw.gGTO);
  EXPECT_GT(r.opening_mm, 1.0);
  EXPECT_EQ(rig.gripper->ReadStatus().raw.gPO, r.raw.gPO);  // and they stay there
}

TEST_P(RobotiqGripperTest, CommandsOutsideTheLimitsAreRejectedBeforeSending) {
  Limits limits;
  limits.min_opening_mm = 5.0;
  limits.max_opening_mm = 80.0;
  limits.max_speed_mm_s = 100.0;
  limits.max_force_n = 120.0;
  Rig rig = MakeRig(GetParam(), {}, limits);
  rig.gripper->Activate();
  const int served = rig.emulator->requests_served();
  ExpectError([&] { rig.gripper->Move(82.0, 50.0, 50.0); }, ErrorCode::kInvalidArgument,
              {"move.opening_mm", "82", "[5, 80]"});
  ExpectError([&] { rig.gripper->Move(2.5, 50.0, 50.0); }, ErrorCode::kInvalidArgument, {"move.opening_mm", "2.5"});
  ExpectError([&] { rig.gripper->Move(40.0, 120.0, 50.0); }, ErrorCode::kInvalidArgument,
              {"move.speed_mm_s", "120", "[20, 100]"});
  ExpectError([&] { rig.gripper->Move(40.0, 10.0, 50.0); }, ErrorCode::kInvalidArgument, {"move.speed_mm_s", "10"});
  ExpectError([&] { rig.gripper->Move(40.0, 50.0, 150.0); }, ErrorCode::kInvalidArgument,
              {"move.force_n", "150", "[20, 120]"});
  ExpectError([&] { rig.gripper->Move(std::nan(""), 50.0, 50.0); }, ErrorCode::kInvalidArgument,
              {"move.opening_mm", "nan"});
  EXPECT_EQ(rig.emulator->requests_served(), served);  // nothing reached the gripper
  EXPECT_FALSE(rig.emulator->command().rGTO);
}

TEST_P(RobotiqGripperTest, LimitsOutsideTheDeviceRangeAreRejected) {
  auto emulator = GetParam() == Link::kTcp ? RobotiqEmulator::StartTcp({}) : RobotiqEmulator::StartRtu({});
  Config config;
  config.limits.max_force_n = 300.0;
  ExpectError([&] { Gripper(Connect(GetParam(), *emulator), config); }, ErrorCode::kInvalidArgument,
              {"robotiq.limits.max_force_n", "300"});
}

TEST_P(RobotiqGripperTest, MoveBeforeActivationIsRefused) {
  Rig rig = MakeRig(GetParam());
  ExpectError([&] { rig.gripper->Move(40.0, 50.0, 50.0); }, ErrorCode::kFailedPrecondition, {"Activate"});
}

TEST_P(RobotiqGripperTest, ModbusExceptionIsReportedAndTheGripperStopped) {
  Rig rig = MakeRig(GetParam());
  rig.gripper->Activate();
  rig.gripper->Move(0.0, 20.0, 50.0);
  ASSERT_TRUE(rig.emulator->moving());
  rig.emulator->InjectFault(ReplyFault::kException, 1, 4);  // SERVER DEVICE FAILURE on the next request
  ExpectDeviceError([&] { rig.gripper->Move(10.0, 20.0, 50.0); }, DeviceFailure::kDeviceException,
                    {"write 3 registers at 0x03E8", "modbus exception 4", "stop sent"});
  EXPECT_FALSE(rig.emulator->command().rGTO);
  EXPECT_FALSE(rig.emulator->moving());
}

TEST_P(RobotiqGripperTest, IllegalAddressesAreClearErrors) {
  Rig rig = MakeRig(GetParam());
  uint16_t value[1];
  ExpectDeviceError([&] { rig.gripper->link().ReadRegisters(0x0100, value); }, DeviceFailure::kDeviceException,
                    {"read 1 registers at 0x0100", "modbus exception 2", "Illegal data address"});
  const uint16_t status[3] = {0, 0, 0};
  ExpectDeviceError([&] { rig.gripper->link().WriteRegisters(kStatusAddress, status); },
                    DeviceFailure::kDeviceException, {"write 3 registers at 0x07D0", "modbus exception 2"});
  uint16_t four[4];  // one register past the status block
  ExpectDeviceError([&] { rig.gripper->link().ReadRegisters(kStatusAddress, four); }, DeviceFailure::kDeviceException,
                    {"exception 2"});
  EXPECT_NO_THROW(rig.gripper->ReadStatus());  // the link is still good afterwards
}

TEST_P(RobotiqGripperTest, LostAnswerTimesOutAndTheGripperIsStopped) {
  Rig rig = MakeRig(GetParam());
  rig.gripper->Activate();
  rig.emulator->InjectFault(ReplyFault::kNoReply);  // the move is executed, its answer lost
  ExpectDeviceError([&] { rig.gripper->Move(0.0, 20.0, 50.0); }, DeviceFailure::kTimeout,
                    {"timed out after 500 ms", "stop sent"});
  EXPECT_FALSE(rig.emulator->command().rGTO);
  EXPECT_FALSE(rig.emulator->moving());
  EXPECT_FALSE(rig.gripper->ReadStatus().moving);
}

TEST_P(RobotiqGripperTest, SilentGripperReportsTheFailedStopToo) {
  Rig rig = MakeRig(GetParam());
  rig.gripper->Activate();
  rig.emulator->InjectFault(ReplyFault::kNoReply, 100);
  ExpectDeviceError([&] { rig.gripper->ReadStatus(); }, DeviceFailure::kTimeout, {"timed out", "stop failed too"});
}

TEST_P(RobotiqGripperTest, MalformedAnswerIsReportedAndTheGripperStopped) {
  Rig rig = MakeRig(GetParam());
  rig.gripper->Activate();
  rig.gripper->Move(0.0, 20.0, 50.0);
  rig.emulator->InjectFault(ReplyFault::kWrongCount);  // status answer with 2 registers instead of 3
  ExpectDeviceError([&] { rig.gripper->ReadStatus(); }, DeviceFailure::kMalformedFrame,
                    {"read 3 registers at 0x07D0", "stop sent"});
  EXPECT_FALSE(rig.emulator->moving());

  rig.gripper->Move(0.0, 20.0, 50.0);  // the link recovers: a new move runs
  EXPECT_TRUE(rig.emulator->moving());
  rig.emulator->InjectFault(ReplyFault::kWrongCount);  // write answer echoing 2 registers
  ExpectDeviceError([&] { rig.gripper->Move(5.0, 20.0, 50.0); }, DeviceFailure::kMalformedFrame, {"stop sent"});
  EXPECT_FALSE(rig.emulator->moving());
}

TEST_P(RobotiqGripperTest, MinorFaultIsReportedInTheStatus) {
  Rig rig = MakeRig(GetParam());
  const Registers go_without_activation = EncodeCommand(Command{.rACT = false, .rGTO = true, .rPR = 100});
  rig.gripper->link().WriteRegisters(kCommandAddress, go_without_activation);
  const Reading r = rig.gripper->ReadStatus();
  EXPECT_EQ(r.fault, kFaultActivationBit);
  EXPECT_EQ(r.fault_name, "activation bit must be set first");
  EXPECT_FALSE(r.moving);
}

TEST_P(RobotiqGripperTest, MajorFaultStopsTheWaitAndAResetClearsIt) {
  Rig rig = MakeRig(GetParam());
  rig.gripper->Activate();
  rig.gripper->Move(0.0, 20.0, 50.0);
  rig.emulator->raise_fault(kFaultOverCurrent);
  ExpectDeviceError([&] { rig.gripper->WaitUntilStopped(kSettle); }, DeviceFailure::kDeviceFault,
                    {"fault 14 (over-current)", "stop sent"});
  EXPECT_FALSE(rig.emulator->command().rGTO);
  rig.gripper->Activate();  // the reset clears the fault
  EXPECT_EQ(rig.gripper->ReadStatus().fault, kFaultNone);
  rig.gripper->Move(60.0, 150.0, 50.0);
  EXPECT_NEAR(rig.gripper->WaitUntilStopped(kSettle).opening_mm, 60.0, kCountMm);
}

TEST_P(RobotiqGripperTest, TruncatedAnswerTimesOutAndTheGripperIsStopped) {
  Rig rig = MakeRig(GetParam());
  rig.gripper->Activate();
  rig.gripper->Move(0.0, 20.0, 50.0);
  rig.emulator->InjectFault(ReplyFault::kTruncated);  // half a status answer, then silence
  ExpectDeviceError([&] { rig.gripper->ReadStatus(); }, DeviceFailure::kTimeout,
                    {"read 3 registers at 0x07D0", "stop sent"});
  EXPECT_FALSE(rig.emulator->moving());
  EXPECT_NO_THROW(rig.gripper->ReadStatus());  // no stale bytes left on the link
}

TEST(RobotiqGripperTcp, ANewConnectionTakesOverAndTheOldOneFailsClearly) {
  Rig rig = MakeRig(Link::kTcp);
  rig.gripper->Activate();
  // The gateway reconnecting after a link loss: the adapter serves the newest master, the device state persists.
  Gripper second(Connect(Link::kTcp, *rig.emulator), Config{});
  EXPECT_TRUE(second.ReadStatus().activated);
  try {
    rig.gripper->ReadStatus();
    ADD_FAILURE() << "the replaced connection still answered";
  } catch (const DeviceError& error) {
    EXPECT_TRUE(error.failure() == DeviceFailure::kIo || error.failure() == DeviceFailure::kTimeout) << error.what();
    EXPECT_NE(std::string(error.what()).find("modbus tcp 127.0.0.1"), std::string::npos) << error.what();
  }
}

TEST(RobotiqGripperRtu, BadCrcIsReportedAndTheGripperStopped) {
  Rig rig = MakeRig(Link::kRtu);
  rig.gripper->Activate();
  rig.gripper->Move(0.0, 20.0, 50.0);
  rig.emulator->InjectFault(ReplyFault::kBadCrc);
  ExpectDeviceError([&] { rig.gripper->ReadStatus(); }, DeviceFailure::kMalformedFrame, {"CRC", "stop sent"});
  EXPECT_FALSE(rig.emulator->moving());
}

INSTANTIATE_TEST_SUITE_P(RobotiqLinks, RobotiqGripperTest, ::testing::Values(Link::kTcp, Link::kRtu),
                         [](const auto& info) { return info.param == Link::kTcp ? "Tcp" : "Rtu"; });

}  // namespace
}  // namespace graspsim::drivers::robotiq
