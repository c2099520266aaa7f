// One interface over every real gripper driver, in SI units, so that one controller (the work cycle's approach,
// grasp, lift, release; the gateway's command loop) runs any of them. The drivers underneath keep their native
// units (mm, mm/s, counts) and their limits: a command outside them throws kInvalidArgument naming the driver's
// field; a link failure throws DeviceError with the device already stopped.
#pragma once

#include <memory>
#include <string>

namespace graspsim::drivers {

namespace robotiq { class Gripper; }
namespace pg70 { class Gripper; }

struct GripperReading {
  double opening_m = 0.0;       // distance between the fingers
  double current_a = 0.0;       // motor current
  bool moving = false;
  bool object_detected = false;  // stopped by something between the fingers
  std::string fault;             // empty when none
};

class GripperDevice {
 public:
  virtual ~GripperDevice() = default;
  virtual std::string Name() const = 0;
  // Makes the gripper ready to move (Robotiq: activation; PG70: reference run).
  virtual void Initialize() = 0;
  // Moves the fingers toward `opening_m` at `speed_m_s`; closing on an object stops there and holds it with
  // about `force_n`. Returns at once; Read() tells when the fingers stop.
  virtual void MoveTo(double opening_m, double speed_m_s, double force_n) = 0;
  virtual void Stop() = 0;
  virtual GripperReading Read() = 0;
};

std::unique_ptr<GripperDevice> MakeGripperDevice(std::unique_ptr<robotiq::Gripper> gripper);
// The PG70 regulates current, not force: `newton_per_amp` converts (57 N/A: 200 N at 3.5 A, datasheet PG 70).
std::unique_ptr<GripperDevice> MakeGripperDevice(std::unique_ptr<pg70::Gripper> gripper, double newton_per_amp = 57.0);

}  // namespace graspsim::drivers
