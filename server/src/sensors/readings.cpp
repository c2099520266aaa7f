#include "sensors/readings.h"

#include <algorithm>
#include <cmath>

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "collision/tactile_rays.h"
#include "core/error.h"

namespace graspsim {

TactileFrame ReadTactileArray(const SceneModel& model, const SceneState& state, size_t pad) {
  const TactileArraySpec& spec = model.tactile_arrays.at(pad);
  TactileFrame frame;
  frame.rows = spec.rows;
  frame.cols = spec.cols;
  const size_t texels = size_t{spec.rows} * spec.cols;
  frame.forces.assign(texels, Vec3::Zero());
  frame.intensities.assign(texels, 0);

  // The simulation sizes pad_forces only once it has stepped: a scene that never ran reads as untouched.
  if (pad < state.pad_forces.size() && !state.pad_forces[pad].empty()) {
    const std::vector<Vec3>& element_forces = state.pad_forces[pad];
    const size_t n = std::min(spec.ElementCount(), element_forces.size());
    for (size_t i = 0; i < n; ++i) {
      const auto [row, col] = ElementTexel(spec, static_cast<uint32_t>(i));
      frame.forces[size_t{row} * spec.cols + col] += element_forces[i];
    }
  }

  // World → pad frame: only the rotation matters for forces.
  const Pose& link = state.body_poses.at(model.body_index.at(spec.body_id));
  const Quat world_to_pad = (link * spec.origin).orientation.conjugate();
  const double max_intensity = spec.max_intensity;
  for (size_t t = 0; t < texels; ++t) {
    Vec3& force = frame.forces[t];
    force = world_to_pad * force;
    // Pressing pushes the pad along its −z (into the foam); +z would be the object pulling, which a foam sensor
    // cannot feel (the contact law never pulls; this is a guard, not a case).
    const double scaled = spec.intensity_per_newton * std::max(0.0, -force.z());
    // Saturate before rounding so that huge (or infinite) forces cannot overflow the integer conversion.
    const uint16_t intensity = !(scaled < max_intensity)
                                   ? static_cast<uint16_t>(spec.max_intensity)
                                   : static_cast<uint16_t>(std::lround(scaled));
    frame.intensities[t] = intensity;
    frame.intensity_sum += intensity;
    frame.force_sum += force;
  }
  return frame;
}

namespace {

// A finger is a prismatic joint with no prismatic joint below it: a linear axis that carries the gripper (the
// z axis of "schunk_pg70_on_z_axis") is not one.
bool IsFinger(const SceneModel& model, const RobotSpec& robot, const JointSpec& joint) {
  if (joint.type != JointType::kPrismatic) return false;
  std::vector<std::string> below = {joint.child_body};  // bodies in the joint's subtree
  for (const std::string& id : robot.joint_ids) {  // topological order: parents before children
    const JointSpec& other = model.joints[model.joint_index.at(id)];
    if (std::find(below.begin(), below.end(), other.parent_body) == below.end()) continue;
    if (other.type == JointType::kPrismatic) return false;
    below.push_back(other.child_body);
  }
  return true;
}

}  // namespace

GripperReading ReadGripper(const SceneModel& model, const SceneState& state, const RobotSpec& robot) {
  GripperReading reading;
  bool have_driver = false;
  for (const std::string& id : robot.joint_ids) {
    const size_t index = model.joint_index.at(id);
    const JointSpec& joint = model.joints[index];
    if (!IsFinger(model, robot, joint)) continue;
    if (index < state.joint_positions.size()) reading.finger_distance += state.joint_positions[index];
    // The first independent finger is the one the motor drives; mimic fingers follow it.
    if (have_driver || joint.mimic) continue;
    have_driver = true;
    if (index < state.joint_velocities.size()) reading.finger_velocity = state.joint_velocities[index];
    if (const auto actuator = state.actuators.find(index); actuator != state.actuators.end()) {
      reading.motor_current = actuator->second.state.current;
    }
  }
  return reading;
}

ForceTorqueReading ReadForceTorque(const SceneModel& model, const SceneState& state, size_t joint) {
  const JointSpec& spec = model.joints.at(joint);
  // Joint wrenches come from graspsim's recursive Newton–Euler with its contact forces; another engine's step
  // leaves them at zero, which would read as an unloaded sensor.
  if (model.simulation.engine != PhysicsEngineKind::kGraspsim) {
    throw Error(ErrorCode::kFailedPrecondition, "sensor '" + spec.id +
                                                    "': force/torque sensors need the graspsim engine (the scene "
                                                    "runs on another; SimulationParams.engine)");
  }
  ForceTorqueReading reading;
  // The simulation sizes joint_wrenches only once it has stepped: a scene that never ran reads zero.
  if (joint < state.joint_wrenches.size()) {
    reading.force = state.joint_wrenches[joint][0];
    reading.torque = state.joint_wrenches[joint][1];
  }
  return reading;
}

std::string TactileImagePng(const TactileFrame& frame, unsigned max_intensity, unsigned scale) {
  if (frame.rows == 0 || frame.cols == 0 || frame.intensities.size() != size_t{frame.rows} * frame.cols) {
    throw Error(ErrorCode::kInternal, "tactile image: frame of " + std::to_string(frame.intensities.size()) +
                                          " intensities is not " + std::to_string(frame.rows) + " x " +
                                          std::to_string(frame.cols));
  }
  // Image row = texel row (pad y, top to bottom), image column = texel column (pad x).
  cv::Mat gray(static_cast<int>(frame.rows), static_cast<int>(frame.cols), CV_8UC1);
  for (unsigned r = 0; r < frame.rows; ++r) {
    for (unsigned c = 0; c < frame.cols; ++c) {
      const double value = frame.intensities[size_t{r} * frame.cols + c];
      const double level = max_intensity == 0 ? 0 : std::min(1.0, value / max_intensity);
      gray.at<uint8_t>(static_cast<int>(r), static_cast<int>(c)) = static_cast<uint8_t>(std::lround(255 * level));
    }
  }
  // Inferno: perceptually uniform and monotonic in lightness (it reads right in grey print too), and black at
  // zero, so an untouched pad is a black image and the hottest texel is the brightest.
  cv::Mat heat;
  cv::applyColorMap(gray, heat, cv::COLORMAP_INFERNO);
  const int s = static_cast<int>(std::max(1u, scale));
  cv::Mat image;
  cv::resize(heat, image, cv::Size(gray.cols * s, gray.rows * s), 0, 0, cv::INTER_NEAREST);
  std::vector<uint8_t> png;
  if (!cv::imencode(".png", image, png)) throw Error(ErrorCode::kInternal, "tactile image: PNG encoding failed");
  return std::string(png.begin(), png.end());
}

}  // namespace graspsim
