#include "drivers/robotiq/robotiq_gripper.h"

#include <thread>

#include "drivers/common/device_error.h"

namespace graspsim::drivers::robotiq {
namespace {

void CheckLimitWithin(const std::string& field, double value, double low, double high) {
  CheckInRange("robotiq.limits." + field, value, low, high);
}

}  // namespace

Reading ToReading(const Calibration& cal, const Status& s) {
  Reading r;
  r.activated = s.gSTA == ActivationState::kActivated;
  // gOBJ 0 reads "moving toward the request", but fingers only move once activated and without a major fault.
  r.moving = r.activated && s.gGTO && s.gOBJ == ObjectState::kMoving && s.gFLT < kFaultOverTemperature;
  r.object_detected = s.gOBJ == ObjectState::kContactOpening || s.gOBJ == ObjectState::kContactClosing;
  r.opening_mm = OpeningMm(cal, s.gPO);
  r.requested_opening_mm = OpeningMm(cal, s.gPR);
  r.current_ma = CurrentMa(s.gCU);
  r.fault = s.gFLT;
  r.fault_name = FaultName(s.gFLT);
  r.raw = s;
  return r;
}

Gripper::Gripper(std::unique_ptr<modbus::ModbusTransport> link, Config config)
    : link_(std::move(link)), config_(config) {
  const Calibration& cal = config_.calibration;
  const Limits& lim = config_.limits;
  CheckLimitWithin("min_opening_mm", lim.min_opening_mm, 0.0, cal.stroke_mm);
  CheckLimitWithin("max_opening_mm", lim.max_opening_mm, lim.min_opening_mm, cal.stroke_mm);
  CheckLimitWithin("min_speed_mm_s", lim.min_speed_mm_s, cal.min_speed_mm_s, cal.max_speed_mm_s);
  CheckLimitWithin("max_speed_mm_s", lim.max_speed_mm_s, lim.min_speed_mm_s, cal.max_speed_mm_s);
  CheckLimitWithin("min_force_n", lim.min_force_n, cal.min_force_n, cal.max_force_n);
  CheckLimitWithin("max_force_n", lim.max_force_n, lim.min_force_n, cal.max_force_n);
}

void Gripper::StopAndRethrow(const DeviceError& error) {
  std::string outcome = "; stop sent";
  try {
    Command stop = last_;
    stop.rGTO = false;
    Write(stop);
  } catch (const DeviceError& stop_error) {
    outcome = std::string("; stop failed too: ") + stop_error.what();
  }
  throw DeviceError(error.failure(), error.what() + outcome);
}

void Gripper::Write(const Command& command) {
  const Registers registers = EncodeCommand(command);
  link_->WriteRegisters(kCommandAddress, registers);
  last_ = command;
}

void Gripper::Activate() {
  try {
    Write(Command{});  // rACT 0: reset, clears a latched fault
    Write(Command{.rACT = true});
  } catch (const DeviceError& error) {
    StopAndRethrow(error);
  }
  activated_ = false;
  const auto deadline = std::chrono::steady_clock::now() + config_.activation_timeout;
  for (;;) {
    const Reading reading = ReadStatus();
    if (reading.fault >= kFaultOverTemperature) {
      StopAndRethrow(DeviceError(DeviceFailure::kDeviceFault,
                                 link_->Describe() + ": activation failed: fault " + std::to_string(reading.fault) +
                                     " (" + reading.fault_name + ")"));
    }
    if (reading.activated) break;
    if (std::chrono::steady_clock::now() > deadline) {
      StopAndRethrow(DeviceError(DeviceFailure::kTimeout, link_->Describe() + ": activation did not complete within " +
                                                             std::to_string(config_.activation_timeout.count()) +
                                                             " ms"));
    }
    std::this_thread::sleep_for(config_.poll_interval);
  }
  activated_ = true;
}

void Gripper::Move(double opening_mm, double speed_mm_s, double force_n) {
  const Limits& lim = config_.limits;
  CheckInRange("move.opening_mm", opening_mm, lim.min_opening_mm, lim.max_opening_mm);
  CheckInRange("move.speed_mm_s", speed_mm_s, lim.min_speed_mm_s, lim.max_speed_mm_s);
  CheckInRange("move.force_n", force_n, lim.min_force_n, lim.max_force_n);
  if (!activated_) throw Error(ErrorCode::kFailedPrecondition, link_->Describe() + ": move before Activate()");
  const Calibration& cal = config_.calibration;
  try {
    Write(Command{.rACT = true,
                  .rGTO = true,
                  .rPR = PositionCounts(cal, opening_mm),
                  .rSP = SpeedCounts(cal, speed_mm_s),
                  .rFR = ForceCounts(cal, force_n)});
  } catch (const DeviceError& error) {
    StopAndRethrow(error);
  }
}

void Gripper::Stop() {
  Command stop = last_;
  stop.rGTO = false;
  Write(stop);  // a failed stop has nothing safer to fall back on: the error goes to the caller as is
}

Reading Gripper::ReadStatus() {
  Registers registers{};
  try {
    link_->ReadRegisters(kStatusAddress, registers);
  } catch (const DeviceError& error) {
    StopAndRethrow(error);
  }
  return ToReading(config_.calibration, DecodeStatus(registers));
}

Reading Gripper::WaitUntilStopped(std::chrono::milliseconds timeout) {
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  for (;;) {
    const Reading reading = ReadStatus();
    if (reading.fault >= kFaultOverTemperature) {
      StopAndRethrow(DeviceError(DeviceFailure::kDeviceFault, link_->Describe() + ": fault " +
                                                                 std::to_string(reading.fault) + " (" +
                                                                 reading.fault_name + ")"));
    }
    if (!reading.moving) return reading;
    if (std::chrono::steady_clock::now() > deadline) {
      StopAndRethrow(DeviceError(DeviceFailure::kTimeout, link_->Describe() + ": fingers still moving after " +
                                                             std::to_string(timeout.count()) + " ms"));
    }
    std::this_thread::sleep_for(config_.poll_interval);
  }
}

}  // namespace graspsim::drivers::robotiq
