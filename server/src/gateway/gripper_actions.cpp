#include "gateway/gripper_actions.h"

#include "core/error.h"

namespace graspsim::gateway {

std::array<GripperAction, 3> GraspActions(double object_width, double speed, double force, double clearance) {
  const double open = object_width + 2 * clearance;
  return {GripperAction{"approach", open, speed, force}, GripperAction{"grasp", 0.0, speed, force},
          GripperAction{"release", open, speed, force}};
}

drivers::GripperReading RunAction(drivers::GripperDevice& device, const GripperAction& action,
                                  const std::function<void()>& wait, int max_waits) {
  device.MoveTo(action.opening, action.speed, action.force);
  drivers::GripperReading reading;
  for (int i = 0; i < max_waits; ++i) {
    wait();  // at least once: a device may not report the move in the instant after the command
    reading = device.Read();
    if (!reading.moving) return reading;
  }
  throw Error(ErrorCode::kFailedPrecondition, "action '" + action.name + "' on " + device.Name() +
                                                  ": the fingers still move after " + std::to_string(max_waits) +
                                                  " waits");
}

}  // namespace graspsim::gateway
