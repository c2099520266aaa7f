// Schunk PG70 driver against the SMP emulator over a socketpair carrying struct can_frame (these machines have
// no vcan; where the kernel has vcan0 the last test runs the same exchange over two raw CAN sockets). Every
// command and the fragmented GET_STATE answer, limits, SMP error messages, malformed answers and timeouts; after
// every failure the emulated module must be stopped.
#include "drivers/pg70/pg70_gripper.h"

#include <sys/socket.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <memory>
#include <thread>

#include <gtest/gtest.h>

#include "drivers/emulators/pg70_emulator.h"
#include "test_util.h"

namespace graspsim::drivers::pg70 {
namespace {

using emulators::Pg70Emulator;
using test_util::ExpectError;

struct Rig {
  std::unique_ptr<Pg70Emulator> emulator;
  std::unique_ptr<Gripper> gripper;
};

Rig MakeRig(Pg70Emulator::Options options = {}) {
  int fds[2];
  if (socketpair(AF_UNIX, SOCK_SEQPACKET, 0, fds) != 0) throw std::runtime_error("socketpair");
  Rig rig;
  rig.emulator = std::make_unique<Pg70Emulator>(fds[1], options);
  Config config;
  config.module_id = options.module_id;
  config.timeout = std::chrono::milliseconds(500);  // a loaded machine never times out a healthy emulator
  rig.gripper = std::make_unique<Gripper>(std::make_unique<can::CanTransport>(fds[0], "socketpair"), config);
  return rig;
}

// Polls GET_STATE until the module stops moving; the bound is generous (the emulated moves last < 1 s).
smp::State WaitUntilStopped(Gripper& gripper) {
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(10);
  smp::State state = gripper.GetState();
  while ((state.flags & smp::state::kMoving) && std::chrono::steady_clock::now() < deadline) {
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
    state = gripper.GetState();
  }
  return state;
}

template <typename Fn>
void ExpectDeviceError(Fn&& fn, DeviceFailure failure, std::initializer_list<const char*> parts) {
  try {
    fn();
    ADD_FAILURE() << "no DeviceError thrown";
  } catch (const DeviceError& error) {
    EXPECT_EQ(error.failure(), failure) << error.what();
    for (const char* part : parts) EXPECT_NE(std::string(error.what()).find(part), std::string::npos) << error.what();
  }
}

TEST(Pg70Gripper, ReferenceThenMoveToAPosition) {
  Rig rig = MakeRig();
  EXPECT_FALSE(rig.gripper->GetState().flags & smp::state::kReferenced);
  rig.gripper->Reference();
  EXPECT_TRUE(rig.gripper->GetState().flags & smp::state::kReferenced);
  const double estimate = rig.gripper->MovePosition(20.0, 80.0, 200.0, 1.0);
  EXPECT_NEAR(estimate, 50.0 / 80.0, 1e-6);  // 70 -> 20 mm at 80 mm/s
  const smp::State state = WaitUntilStopped(*rig.gripper);
  EXPECT_FLOAT_EQ(state.position_mm, 20.0f);
  EXPECT_EQ(state.velocity_mm_s, 0.0f);
  EXPECT_TRUE(state.flags & smp::state::kPositionReached);
  EXPECT_TRUE(state.flags & smp::state::kMoveEnd);
  EXPECT_EQ(state.error_code, 0);
}

TEST(Pg70Gripper, GripStopsOnTheObjectAndHoldsItsCurrent) {
  Pg70Emulator::Options options;
  options.object_width_mm = 30.0;
  Rig rig = MakeRig(options);
  rig.gripper->Reference();
  rig.gripper->Grip(2.0);
  const smp::State state = WaitUntilStopped(*rig.gripper);
  EXPECT_FLOAT_EQ(state.position_mm, 30.0f);
  EXPECT_FLOAT_EQ(state.current_a, 2.0f);
  EXPECT_FALSE(state.flags & smp::state::kPositionReached);
  rig.gripper->Grip(-1.0);  // a negative current opens
  EXPECT_FLOAT_EQ(WaitUntilStopped(*rig.gripper).position_mm, 70.0f);
}

TEST(Pg70Gripper, MoveVelocityRunsUntilStopped) {
  Rig rig = MakeRig();
  rig.gripper->Reference();
  rig.gripper->MoveVelocity(-5.0, 1.0);  // 70 mm at 5 mm/s: still moving at the stop
  const smp::State moving = rig.gripper->GetState();
  EXPECT_TRUE(moving.flags & smp::state::kMoving);
  EXPECT_FLOAT_EQ(moving.velocity_mm_s, -5.0f);
  rig.gripper->Stop();
  EXPECT_FALSE(rig.emulator->moving());
  const smp::State stopped = rig.gripper->GetState();
  EXPECT_FALSE(stopped.flags & smp::state::kMoving);
  EXPECT_EQ(stopped.velocity_mm_s, 0.0f);
  EXPECT_LT(stopped.position_mm, 70.0f);
  EXPECT_GT(stopped.position_mm, 0.0f);
}

TEST(Pg70Gripper, OtherModulesTrafficIsSkipped) {
  Pg70Emulator::Options options;
  options.chatter = true;
  Rig rig = MakeRig(options);
  rig.gripper->Reference();
  EXPECT_TRUE(rig.gripper->GetState().flags & smp::state::kReferenced);
}

TEST(Pg70Gripper, CommandsOutsideTheLimitsAreRejectedBeforeSending) {
  Rig rig = MakeRig();
  rig.gripper->Reference();
  const int served = rig.emulator->requests_served();
  ExpectError([&] { rig.gripper->MovePosition(75.0, 50.0, 100.0, 1.0); }, ErrorCode::kInvalidArgument,
              {"move_position.position_mm", "75", "[0, 70]"});
  ExpectError([&] { rig.gripper->MovePosition(20.0, 90.0, 100.0, 1.0); }, ErrorCode::kInvalidArgument,
              {"move_position.velocity_mm_s", "90"});
  ExpectError([&] { rig.gripper->MovePosition(20.0, 50.0, 400.0, 1.0); }, ErrorCode::kInvalidArgument,
              {"move_position.acceleration_mm_s2", "400"});
  ExpectError([&] { rig.gripper->MovePosition(20.0, 50.0, 100.0, 5.0); }, ErrorCode::kInvalidArgument,
              {"move_position.current_a", "5", "(0, 3.5]"});
  ExpectError([&] { rig.gripper->MoveVelocity(-100.0, 1.0); }, ErrorCode::kInvalidArgument,
              {"move_velocity.velocity_mm_s", "-100"});
  ExpectError([&] { rig.gripper->MovePosition(20.0, 0.0, 100.0, 1.0); }, ErrorCode::kInvalidArgument,
              {"move_position.velocity_mm_s", "0 is outside (0, 82]"});
  ExpectError([&] { rig.gripper->MoveVelocity(5.0, 0.0); }, ErrorCode::kInvalidArgument, {"move_velocity.current_a"});
  ExpectError([&] { rig.gripper->Grip(-4.0); }, ErrorCode::kInvalidArgument, {"grip.current_a", "-4"});
  ExpectError([&] { rig.gripper->Grip(0.0); }, ErrorCode::kInvalidArgument, {"grip.current_a", "no direction"});
  ExpectError([&] { rig.gripper->Grip(std::nan("")); }, ErrorCode::kInvalidArgument, {"grip.current_a", "nan"});
  EXPECT_EQ(rig.emulator->requests_served(), served);
}

TEST(Pg70Gripper, ModuleErrorIsReportedAndTheModuleStopped) {
  Rig rig = MakeRig();
  ExpectDeviceError([&] { rig.gripper->MoveVelocity(-5.0, 1.0); }, DeviceFailure::kDeviceException,
                    {"module refused command 0xB5: 0xDB", "not referenced", "stop sent"});
  rig.gripper->Reference();
  rig.gripper->MoveVelocity(-5.0, 1.0);
  rig.emulator->InjectFault(Pg70Emulator::Fault::kErrorMessage, 1, smp::kErrorOverCurrent);
  ExpectDeviceError([&] { rig.gripper->GetState(); }, DeviceFailure::kDeviceException,
                    {"error 0xDE", "over current", "stop sent"});
  EXPECT_FALSE(rig.emulator->moving());
}

TEST(Pg70Gripper, LostAnswerTimesOutAndTheModuleIsStopped) {
  Rig rig = MakeRig();
  rig.gripper->Reference();
  rig.emulator->InjectFault(Pg70Emulator::Fault::kSilent);  // the move runs, its answer is lost
  ExpectDeviceError([&] { rig.gripper->MovePosition(0.0, 5.0, 100.0, 1.0); }, DeviceFailure::kTimeout,
                    {"no answer to command 0xB0 within 500 ms", "stop sent"});
  EXPECT_FALSE(rig.emulator->moving());
  EXPECT_FALSE(rig.gripper->GetState().flags & smp::state::kMoving);
}

TEST(Pg70Gripper, SilentModuleReportsTheFailedStopToo) {
  Rig rig = MakeRig();
  rig.emulator->InjectFault(Pg70Emulator::Fault::kSilent, 100);
  ExpectDeviceError([&] { rig.gripper->GetState(); }, DeviceFailure::kTimeout,
                    {"command 0x95", "stop failed too", "command 0x91"});
}

TEST(Pg70Gripper, MalformedAnswerIsReportedAndTheModuleStopped) {
  Rig rig = MakeRig();
  rig.gripper->Reference();
  rig.gripper->MoveVelocity(-5.0, 1.0);
  rig.emulator->InjectFault(Pg70Emulator::Fault::kMalformed);
  ExpectDeviceError([&] { rig.gripper->GetState(); }, DeviceFailure::kMalformedFrame,
                    {"socketpair pg70 module 12", "FRAG_END without FRAG_START", "stop sent"});
  EXPECT_FALSE(rig.emulator->moving());
  EXPECT_TRUE(rig.gripper->GetState().flags & smp::state::kReferenced);  // the link recovers
}

TEST(Pg70Gripper, EmulatorSurvivesBrokenFramingFromTheMaster) {
  int fds[2];
  ASSERT_EQ(socketpair(AF_UNIX, SOCK_SEQPACKET, 0, fds), 0);
  Pg70Emulator emulator(fds[1], {});
  can::CanTransport raw(dup(fds[0]), "raw");
  Gripper gripper(std::make_unique<can::CanTransport>(fds[0], "socketpair"), Config{});
  can_frame stray{};  // a FRAG_END nobody started
  stray.can_id = smp::kToModule + 12;
  stray.can_dlc = 4;
  stray.data[0] = 2;
  stray.data[1] = smp::kFragEnd;
  raw.Send(stray);
  gripper.Reference();  // answered as if nothing had happened
  EXPECT_EQ(emulator.malformed_requests(), 1);
  const smp::Message unknown{0x42};
  for (const can_frame& f : smp::EncodeFrames(smp::kToModule + 12, unknown)) raw.Send(f);
  const auto refusal = raw.Receive(std::chrono::milliseconds(2000));
  ASSERT_TRUE(refusal);
  EXPECT_EQ(refusal->can_id, smp::kFromModule + 12);
  EXPECT_EQ(std::vector<uint8_t>(refusal->data, refusal->data + refusal->can_dlc),
            (std::vector<uint8_t>{0x02, 0x42, smp::kErrorUnknownCommand}));
}

TEST(Pg70Gripper, ModuleIdSelectsTheCanIds) {
  Pg70Emulator::Options options;
  options.module_id = 3;
  Rig rig = MakeRig(options);
  rig.gripper->Reference();
  EXPECT_TRUE(rig.gripper->GetState().flags & smp::state::kReferenced);
}

TEST(Pg70Gripper, SocketCanOpenerNamesAMissingInterface) {
  ExpectDeviceError([] { can::OpenSocketCan("graspsim-nocan", nullptr, 0); }, DeviceFailure::kIo,
                    {"socketcan graspsim-nocan"});
}

TEST(Pg70Gripper, SameExchangeOverVcan0WhereTheKernelHasIt) {
  int bus_a, bus_b;
  try {
    bus_a = can::OpenSocketCan("vcan0", nullptr, 0);
    bus_b = can::OpenSocketCan("vcan0", nullptr, 0);
  } catch (const DeviceError& error) {
    GTEST_SKIP() << "no vcan0 here: " << error.what();
  }
  Pg70Emulator emulator(bus_b, {});
  Gripper gripper(std::make_unique<can::CanTransport>(bus_a, "vcan0"), Config{});
  gripper.Reference();
  gripper.MovePosition(60.0, 80.0, 200.0, 1.0);
  EXPECT_FLOAT_EQ(WaitUntilStopped(gripper).position_mm, 60.0f);
}

}  // namespace
}  // namespace graspsim::drivers::pg70
