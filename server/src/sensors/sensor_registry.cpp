// A scene's sensors by id, and their readings (see sensor_registry.h).
#include "sensors/sensor_registry.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <set>
#include <cstring>
#include <vector>

#include "core/error.h"
#include "core/format.h"
#include "tactile/heat_map.h"

namespace graspsim {
namespace {

constexpr char kGripperSuffix[] = "/gripper";
constexpr size_t kListedSensors = 10;  // an error lists this many available sensors, then a count

bool HasPrismaticJoint(const SceneModel& model, const RobotSpec& robot) {
  return std::any_of(robot.joint_ids.begin(), robot.joint_ids.end(), [&](const std::string& id) {
    return model.joints[model.joint_index.at(id)].type == JointType::kPrismatic;
  });
}

std::string Shortened(const std::string& id) { return id.size() > 80 ? id.substr(0, 80) + "..." : id; }

std::string AvailableSensors(const SceneModel& model) {
  std::vector<std::string> ids;
  for (const TactileArraySpec& pad : model.tactile_arrays) ids.push_back(pad.id);
  for (const RobotSpec& robot : model.robots) {
    if (HasPrismaticJoint(model, robot)) ids.push_back(robot.id + kGripperSuffix);
  }
  std::sort(ids.begin(), ids.end());
  // Then the force/torque sensors: every joint of a robot (ids are in robot order).
  for (const JointSpec& joint : model.joints) ids.push_back(joint.id);
  if (ids.empty()) return "the scene has no sensors (tactile arrays, grippers and joints come with robots)";
  std::string list;
  for (size_t i = 0; i < std::min(ids.size(), kListedSensors); ++i) list += (i ? ", " : "") + ids[i];
  if (ids.size() > kListedSensors) list += " and " + std::to_string(ids.size() - kListedSensors) + " more";
  return "available: " + list;
}

}  // namespace

SensorRef FindSensor(const SceneView& view, const std::string& field, const std::string& id) {
  const SceneModel& model = *view.model;
  if (id.empty()) ThrowInvalidArgument(field + ": empty; name a sensor (" + AvailableSensors(model) + ")");
  if (const auto pad = model.tactile_index.find(id); pad != model.tactile_index.end()) {
    return {SensorRef::Kind::kTactile, pad->second};
  }
  if (id.size() > std::strlen(kGripperSuffix) && id.ends_with(kGripperSuffix)) {
    const std::string robot_id = id.substr(0, id.size() - std::strlen(kGripperSuffix));
    if (const auto robot = model.robot_index.find(robot_id); robot != model.robot_index.end()) {
      if (!HasPrismaticJoint(model, model.robots[robot->second])) {
        ThrowNotFound(field + ": no sensor '" + Shortened(id) + "' in scene '" + view.id + "': robot '" + robot_id +
                      "' has no prismatic joints, so no gripper state; " + AvailableSensors(model));
      }
      return {SensorRef::Kind::kGripper, robot->second};
    }
  }
  if (const auto joint = model.joint_index.find(id); joint != model.joint_index.end()) {
    return {SensorRef::Kind::kForceTorque, joint->second};
  }
  ThrowNotFound(field + ": no sensor '" + Shortened(id) + "' in scene '" + view.id + "'; " + AvailableSensors(model));
}

SensorReading ReadSensor(const SceneView& view, const SensorRef& sensor, const std::string& id) {
  const SceneModel& model = *view.model;
  SensorReading reading{id, view.state.time, {}};
  switch (sensor.kind) {
    case SensorRef::Kind::kTactile:
      reading.value = ReadTactileArray(model, view.state, sensor.index);
      return reading;
    case SensorRef::Kind::kGripper:
      reading.value = ReadGripper(model, view.state, model.robots[sensor.index]);
      return reading;
    case SensorRef::Kind::kForceTorque:
      reading.value = ReadForceTorque(model, view.state, sensor.index);
      return reading;
  }
  throw Error(ErrorCode::kInternal, "sensor '" + id + "': unknown sensor kind");
}

TactileHeatMap TactileHeatMapOf(const SceneView& view, const std::string& id, unsigned scale) {
  constexpr unsigned kDefaultScale = 20, kMaxSide = 4096;  // px per texel; px
  const SensorRef sensor = FindSensor(view, "sensor_id", id);
  if (sensor.kind != SensorRef::Kind::kTactile) {
    ThrowInvalidArgument("sensor_id: '" + id + "' is not a tactile array; images are of tactile arrays only");
  }
  const TactileArraySpec& pad = view.model->tactile_arrays[sensor.index];
  if (scale == 0) scale = kDefaultScale;
  const unsigned longest = std::max(pad.rows, pad.cols);
  if (uint64_t{scale} * longest > kMaxSide) {
    ThrowInvalidArgument("scale: " + std::to_string(scale) + " px per texel makes the " + std::to_string(pad.cols) +
                         " x " + std::to_string(pad.rows) + " texels of '" + id + "' an image of " +
                         std::to_string(uint64_t{scale} * pad.cols) + " x " + std::to_string(uint64_t{scale} * pad.rows) +
                         " px; at most " + std::to_string(kMaxSide) + " px per side, i.e. scale <= " +
                         std::to_string(kMaxSide / longest));
  }
  const TactileFrame frame = ReadTactileArray(*view.model, view.state, sensor.index);
  return {TactileImagePng(frame, pad.max_intensity, scale), pad.cols * scale, pad.rows * scale};
}

void CheckSensorStream(double rate_hz, double max_rate_hz, const std::vector<std::string>& ids) {
  if (!std::isfinite(rate_hz) || rate_hz <= 0) {
    ThrowInvalidArgument("rate_hz: " + FormatNumber(rate_hz) + " Hz; give a finite rate > 0");
  }
  if (rate_hz > max_rate_hz) {
    ThrowInvalidArgument("rate_hz: " + FormatNumber(rate_hz) + " Hz is above the server's limit of " +
                         FormatNumber(max_rate_hz) + " Hz (--watch-max-rate-hz)");
  }
  if (ids.empty()) ThrowInvalidArgument("sensor_ids: empty; name at least one sensor");
  std::set<std::string> seen;
  for (size_t i = 0; i < ids.size(); ++i) {
    if (!seen.insert(ids[i]).second) {
      ThrowInvalidArgument("sensor_ids[" + std::to_string(i) + "]: '" + ids[i].substr(0, 80) + "' is listed twice");
    }
  }
}

}  // namespace graspsim
