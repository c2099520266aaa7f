// A scene's sensors by id, and one reading of each. A scene's sensors: each tactile array (its id,
// "<robot>/<pad>"), for each robot with prismatic joints its gripper state ("<robot>/gripper"), and for each joint
// of a robot its 6-axis force/torque sensor (the joint's id, "<robot>/<joint>").
#pragma once

#include <cstddef>
#include <string>
#include <variant>
#include <vector>

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

// The heat map of the tactile array `id` names (tactile/heat_map.h), `scale` px per texel (0: 20, a PG70 pad
// becomes 120 x 280 px). INVALID_ARGUMENT naming `sensor_id` for a sensor that is not a tactile array, and `scale`
// for an image over 4096 px a side.
struct TactileHeatMap {
  std::string png;
  unsigned width = 0, height = 0;
};
TactileHeatMap TactileHeatMapOf(const SceneView& view, const std::string& id, unsigned scale);

// The checks of a sensor stream's request: a finite rate > 0 up to `max_rate_hz` (the server's limit), at least
// one id, none twice. INVALID_ARGUMENT naming rate_hz or sensor_ids[i]; the ids are checked against a scene by
// FindSensor when the stream starts.
void CheckSensorStream(double rate_hz, double max_rate_hz, const std::vector<std::string>& ids);

}  // namespace graspsim
