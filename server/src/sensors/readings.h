// Sensor readings as the real devices deliver them (PAPERS.md part B): a tactile pad's frame in the structure of
// the Weiss DSACON32 controller, and the PG70's gripper state. Computed from a scene's model and state after a
// simulation step; the physics fills SceneState::pad_forces (per sensing element, world frame) and
// SceneState::joint_wrenches (per joint, child frame).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "core/math.h"
#include "world/model.h"
#include "world/state.h"

namespace graspsim {

// One DSACON32-style frame: rows × cols texels, row-major (row along pad y, col along pad x).
struct TactileFrame {
  unsigned rows = 0, cols = 0;
  std::vector<uint16_t> intensities;  // 0..max_intensity: round(intensity_per_newton · texel normal force), saturated
  std::vector<Vec3> forces;           // per texel: the force the object exerts on the pad, pad frame, N
  uint64_t intensity_sum = 0;
  Vec3 force_sum = Vec3::Zero();      // pad frame, N
};

// The frame of tactile array `pad` (index into model.tactile_arrays) in `state`. The pad's +z points out of the
// foam toward what it touches, so an object pressing on the pad pushes it along −z: the texel's normal force is
// max(0, −z) of its force (a force along +z would pull the foam off and reads 0).
TactileFrame ReadTactileArray(const SceneModel& model, const SceneState& state, size_t pad);

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

// A tactile frame as a PNG heat map (OpenCV colormap), `scale` pixels per texel.
std::string TactileImagePng(const TactileFrame& frame, unsigned max_intensity, unsigned scale);

}  // namespace graspsim
