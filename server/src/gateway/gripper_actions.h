// The gripper's part of the work cycle's actions (workcycle/work_cycle.h) as moves of any GripperDevice, so the
// same controller runs a real gripper behind the drivers and the simulated PG70 (SimulatedGripper):
//   approach  open to the object's width plus twice the clearance
//   grasp     close toward zero with the gripping force: the fingers stop on the object and hold it
//   release   open to the approach width again
// The cycle's lift and move down drive the z axis, which the gateway's grippers do not have; they stay in the
// simulation. The tactile force control of the simulated grasp needs pads, which real devices here lack.
#pragma once

#include <array>
#include <functional>
#include <string>

#include "drivers/device/gripper_device.h"

namespace graspsim::gateway {

struct GripperAction {
  std::string name;
  double opening = 0;  // m
  double speed = 0;    // m/s
  double force = 0;    // N
};

std::array<GripperAction, 3> GraspActions(double object_width, double speed, double force, double clearance = 0.01);

// Starts `action` on `device`, then calls `wait()` (sleep, or step a simulation) and reads until the fingers
// stop, at most `max_waits` times; returns the last reading. Throws Error(kFailedPrecondition) naming the
// action when they are still moving then.
drivers::GripperReading RunAction(drivers::GripperDevice& device, const GripperAction& action,
                                  const std::function<void()>& wait, int max_waits);

}  // namespace graspsim::gateway
