// Sensor readings as the real devices deliver them (PAPERS.md part B), other than the tactile pads'
// (tactile/tactile_frame.h): the PG70's gripper state and 6-axis force/torque on a joint. Computed from a scene's
// model and state after a simulation step; the physics fills SceneState::joint_wrenches (per joint, child frame).
#pragma once

#include <cstddef>

#include "core/math.h"
#include "world/model.h"
#include "world/state.h"

namespace graspsim {

// The Schunk PG70's own sensor: jaw opening, motor current, finger speed.
struct GripperReading {
  // m: the sum of the robot's prismatic finger joint positions (0 = closed). Fingers are prismatic joints with
  // no prismatic joint below them, so a linear axis carrying the gripper does not count.
  double finger_distance = 0;
  double motor_current = 0;    // A: the driving joint's motor, 0 when undriven
  double finger_velocity = 0;  // m/s: the driving (independent) finger joint's velocity
};
GripperReading ReadGripper(const SceneModel& model, const SceneState& state, const RobotSpec& robot);

// A 6-axis force/torque sensor on a joint (a wrist flange): the wrench the joint transmits from its parent side to
// its child side, i.e. what the child body and everything it carries receive through the joint, in the joint's
// child frame (the child body's frame), torque about that frame's origin. A gripper hanging still from its wrist
// reads −(m g) of the gripper and what it holds, expressed in the child frame. Zero before the first step.
struct ForceTorqueReading {
  Vec3 force = Vec3::Zero();   // N, child frame
  Vec3 torque = Vec3::Zero();  // N m, child frame, about its origin
};
ForceTorqueReading ReadForceTorque(const SceneModel& model, const SceneState& state, size_t joint);

}  // namespace graspsim
