// Sensor ids of TactileService and their readings as messages. A scene's sensors: each tactile array (its id,
// "<robot>/<pad>"), for each robot with prismatic joints, its gripper state ("<robot>/gripper"), and each joint
// of a robot, its 6-axis force/torque sensor (the joint's id, "<robot>/<joint>").
#pragma once

#include <string>

#include "graspsim/v1/tactile.pb.h"
#include "sensors/readings.h"
#include "world/scene.h"

namespace graspsim::rpc {

struct SensorRef {
  enum class Kind { kTactile, kGripper, kForceTorque };
  Kind kind = Kind::kTactile;
  size_t index = 0;  // into the model's tactile_arrays, robots or joints, by kind
};

// The sensor `id` names in `view`. Errors name `field` and the id: INVALID_ARGUMENT when empty, NOT_FOUND
// listing the scene's sensors when unknown.
SensorRef FindSensor(const SceneView& view, const std::string& field, const std::string& id);

// The readings as messages: intensities and forces packed little-endian (uint16, float32 x y z per texel).
void ToProto(const TactileFrame& frame, v1::TactileReading* out);
void ToProto(const GripperReading& reading, v1::GripperReading* out);
void ToProto(const ForceTorqueReading& reading, v1::ForceTorqueReading* out);

// One reading of `sensor` in `view`'s state, time stamped with the state's time.
void ReadSensor(const SceneView& view, const SensorRef& sensor, const std::string& id, v1::SensorReading* out);

}  // namespace graspsim::rpc
