// Robotiq 2F-85 device logic over any ModbusTransport (TCP or RTU). Units at this interface: opening in mm
// (85 open, 0 closed), speed in mm/s, force in N, current in mA. Every command is checked against the configured
// limits before anything is sent; a bad value throws kInvalidArgument naming the field and the value. Any link
// failure during a command or a status read throws DeviceError after a best-effort stop (rGTO = 0), so a gripper
// whose master lost track of it is left stopped, never still moving toward a stale request.
// Not thread-safe: one caller at a time (the gateway's device thread), as a Modbus master link allows anyway.
#pragma once

#include <chrono>
#include <memory>
#include <string>

#include "drivers/common/device_error.h"
#include "drivers/modbus/modbus_transport.h"
#include "drivers/robotiq/robotiq_registers.h"

namespace graspsim::drivers::robotiq {

// Bounds of the commands this gripper accepts; must lie inside the calibration's device ranges.
struct Limits {
  double min_opening_mm = 0.0, max_opening_mm = 85.0;
  double min_speed_mm_s = 20.0, max_speed_mm_s = 150.0;
  double min_force_n = 20.0, max_force_n = 235.0;
};

struct Config {
  Calibration calibration;
  Limits limits;
  std::chrono::milliseconds activation_timeout{5000};
  std::chrono::milliseconds poll_interval{10};
};

struct Reading {
  bool activated = false;        // gSTA == activated
  bool moving = false;           // activated, gGTO set, gOBJ == moving, no major fault
  bool object_detected = false;  // stopped on contact (gOBJ 1 or 2)
  double opening_mm = 0.0;       // from gPO
  double requested_opening_mm = 0.0;  // from gPR
  double current_ma = 0.0;       // from gCU
  uint8_t fault = 0;             // gFLT
  std::string fault_name;
  Status raw;
};

class Gripper {
 public:
  // Throws kInvalidArgument if the limits leave the calibration's ranges.
  Gripper(std::unique_ptr<modbus::ModbusTransport> link, Config config);

  // Reset (rACT 0, which also clears a latched fault) then activate (rACT 1) and wait for gSTA == activated;
  // throws on a major fault or after activation_timeout, the gripper stopped (rGTO 0) in both cases.
  void Activate();
  // Starts a move; does not wait. Throws kFailedPrecondition before Activate().
  void Move(double opening_mm, double speed_mm_s, double force_n);
  void Stop();
  Reading ReadStatus();
  // Polls until the fingers stop (target reached or object); throws DeviceError(kTimeout) after `timeout` and
  // DeviceError(kDeviceFault) on a major fault, stopping the gripper in both cases.
  Reading WaitUntilStopped(std::chrono::milliseconds timeout);

  const Config& config() const { return config_; }
  modbus::ModbusTransport& link() { return *link_; }

 private:
  void Write(const Command& command);
  [[noreturn]] void StopAndRethrow(const DeviceError& error);

  std::unique_ptr<modbus::ModbusTransport> link_;
  Config config_;
  Command last_{};
  bool activated_ = false;
};

Reading ToReading(const Calibration& calibration, const Status& status);

}  // namespace graspsim::drivers::robotiq
