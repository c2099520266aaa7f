// The simulated PG70 behind the drivers' GripperDevice interface (drivers/device/gripper_device.h), so that one
// controller runs the real gripper through the gateway and this twin in the simulation. It owns a private copy
// of a scene's state and its own Simulation; the scene itself is never changed.
//
// Commands act like the module's MOVE_POS: the finger drive (the built-in PG70 drive, physics/builtin_drives.h) in
// position mode toward opening/2 per finger (two mirrored fingers), its speed capped at speed/2 per finger and
// its current limited to force / (200 N / 3.5 A), the PG70's force constant. Time advances only in Advance():
// a prediction steps it to the times of the real device's readings.
#pragma once

#include <memory>
#include <string>

#include "drivers/device/gripper_device.h"
#include "physics/simulation.h"
#include "world/model.h"
#include "world/state.h"

namespace graspsim::gateway {

class SimulatedGripper : public drivers::GripperDevice {
 public:
  // `gripper_id`: a robot with a prismatic joint "<id>/finger_left_joint" (the built-in PG70s); throws
  // Error(kNotFound) or kInvalidArgument naming the field otherwise.
  SimulatedGripper(std::shared_ptr<const SceneModel> model, SceneState state, const std::string& gripper_id);

  std::string Name() const override { return "simulated pg70 '" + gripper_id_ + "'"; }
  void Initialize() override {}  // the simulated drive needs no reference run
  void MoveTo(double opening_m, double speed_m_s, double force_n) override;
  void Stop() override;
  drivers::GripperReading Read() override;

  // Puts the fingers at `opening_m` (clamped to the joint's range), at rest: the real device's start state.
  void SetOpening(double opening_m);
  // Steps the simulation by whole time steps to `seconds` since construction (no step when already there).
  void AdvanceTo(double seconds);
  double time() const { return state_.time - start_time_; }  // s since construction
  // The intensity sum of the gripper's tactile pads (0 without pads).
  double TactileSum() const;

 private:
  std::shared_ptr<const SceneModel> model_;
  Simulation simulation_;
  SceneState state_;
  std::string gripper_id_;
  size_t robot_ = 0, finger_ = 0;
  double start_time_ = 0;
};

}  // namespace graspsim::gateway
