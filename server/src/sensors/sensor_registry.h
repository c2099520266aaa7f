// A scene's sensors by id, and one reading of each. A scene's sensors: each tactile array (its id,
// "<robot>/<pad>"), for each robot with prismatic joints its gripper state ("<robot>/gripper"), and for each joint
// of a robot its 6-axis force/torque sensor (the joint's id, "<robot>/<joint>").
#pragma once

#include <cstddef>
#include <string>
#include <variant>

#include "sensors/readings.h"
#include "tactile/tactile_frame.h"
#include "world/scene.h"

namespace graspsim {

struct SensorRef {
  enum class Kind { kTactile, kGripper, kForceTorque };
  Kind kind = Kind::kTactile;
  size_t index = 0;  // into the model's tactile_arrays, robots or joints, by kind
};

// The sensor `id` names in `view`. Errors name `field` and the id: INVALID_ARGUMENT when empty, NOT_FOUND
// listing the scene's sensors when unknown.
SensorRef FindSensor(const SceneView& view, const std::string& field, const std::string& id);

struct SensorReading {
  std::string sensor_id;
  double time = 0;  // s: the state's simulated time
  std::variant<TactileFrame, GripperReading, ForceTorqueReading> value;  // by SensorRef::Kind
};

// One reading of `sensor` (named `id`) in `view`'s state.
SensorReading ReadSensor(const SceneView& view, const SensorRef& sensor, const std::string& id);

}  // namespace graspsim
