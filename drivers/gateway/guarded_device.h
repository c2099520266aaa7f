// The gateway's safety layer around one GripperDevice: every command is checked against the configured limits
// before it reaches the driver (a refusal names the field, the value and the bounds, and changes nothing); an
// e-stop stops the fingers and latches, so moves are refused until Initialize(); and all calls are serialised
// by one mutex, so the watchdog thread can stop the device while the device thread is between commands.
// Units SI: m, m/s, N, A.
#pragma once

#include <memory>
#include <mutex>
#include <string>

#include "drivers/device/gripper_device.h"

namespace graspsim::drivers::gateway {

struct Limits {
  double min_opening = 0, max_opening = 0;  // m
  double min_speed = 0, max_speed = 0;      // m/s
  double min_force = 0, max_force = 0;      // N
  double max_current = 0;                   // A (rated motor current; not a command bound)
};

// The native limits of each supported gripper (its driver's defaults, in SI units).
Limits RobotiqLimits();
Limits Pg70Limits();
// `overrides` is "name=value,...", names as in Limits (e.g. "max_speed=0.05,max_force=100"). Each value must lie
// within `native`; throws Error(kInvalidArgument) naming the entry otherwise.
Limits ApplyLimitOverrides(const Limits& native, const std::string& overrides);

class GuardedDevice {
 public:
  GuardedDevice(std::string id, std::string kind, std::string link, std::unique_ptr<GripperDevice> device,
                Limits limits);

  const std::string& id() const { return id_; }
  const std::string& kind() const { return kind_; }
  const std::string& link() const { return link_; }
  const Limits& limits() const { return limits_; }

  // Throws Error(kInvalidArgument) for a value outside the limits, Error(kFailedPrecondition) while e-stopped,
  // and the driver's DeviceError. A move uses the speed and force set last (SetSpeed, SetForce; at first the
  // limits' minimum force and half the maximum speed).
  void Move(double opening, double speed, double force);
  void MoveTo(double opening);
  void SetSpeed(double speed);
  void SetForce(double force);
  void Stop();
  // Stops and latches; the latch holds even when the stop could not be delivered (the error is rethrown).
  void EmergencyStop();
  // Activation or reference run; clears the latch.
  void Initialize();
  GripperReading Read();
  bool estopped() const;

 private:
  void CheckMove(double opening, double speed, double force) const;

  const std::string id_, kind_, link_;
  std::unique_ptr<GripperDevice> device_;
  const Limits limits_;
  mutable std::mutex mutex_;
  double speed_, force_;
  bool estopped_ = false;
};

}  // namespace graspsim::drivers::gateway
