#include "recording/ros2_channels.h"

#include <cmath>

#include "recording/ros2_messages.h"
#include "sensors/readings.h"
#include "tactile/tactile_frame.h"
#include "world/model.h"
#include "world/state.h"

namespace graspsim::recording {

uint32_t Ros2Channels::Channel(const std::string& topic, const char* type_name) {
  auto it = channels_.find(topic);
  if (it != channels_.end()) return it->second;
  const ros2::MessageType* types[] = {&ros2::kTFMessage, &ros2::kJointState, &ros2::kFloat32MultiArray,
                                      &ros2::kWrenchStamped, &ros2::kPointCloud2};
  std::string definition;
  for (const auto* type : types) {
    if (std::string(type->name) == type_name) definition = type->definition;
  }
  const uint32_t id = writer_->AddChannel({topic, "cdr", type_name, "ros2msg", definition});
  channels_.emplace(topic, id);
  return id;
}

void Ros2Channels::Write(const SceneSnapshot& frame, FrameReadings& readings) {
  const SceneModel& model = *frame.model;
  const SceneState& state = *frame.state;
  const uint64_t time_ns = static_cast<uint64_t>(std::llround(state.time * 1e9));
  const ros2::Stamp stamp = ros2::StampOf(state.time);

  const uint32_t tf = Channel("/tf", ros2::kTFMessage.name);
  if (writer_->Wanted(tf)) {
    std::vector<ros2::Transform> transforms;
    transforms.reserve(model.bodies.size());
    for (size_t i = 0; i < model.bodies.size(); ++i) {
      transforms.push_back({"world", model.bodies[i].id, state.body_poses[i]});
    }
    writer_->Write(tf, time_ns, ros2::EncodeTFMessage(stamp, transforms));
  }

  std::vector<std::string> names;
  std::vector<double> positions, velocities, efforts;
  for (size_t j = 0; j < model.joints.size(); ++j) {
    if (model.joints[j].type == JointType::kFixed) continue;
    names.push_back(model.joints[j].id);
    positions.push_back(state.joint_positions[j]);
    velocities.push_back(j < state.joint_velocities.size() ? state.joint_velocities[j] : 0.0);
  }
  if (!names.empty()) {
    const uint32_t joints = Channel("/joint_states", ros2::kJointState.name);
    if (writer_->Wanted(joints)) {
      writer_->Write(joints, time_ns, ros2::EncodeJointState(stamp, names, positions, velocities, efforts));
    }
  }

  for (size_t pad = 0; pad < model.tactile_arrays.size(); ++pad) {
    const uint32_t channel = Channel("/tactile/" + model.tactile_arrays[pad].id, ros2::kFloat32MultiArray.name);
    if (!writer_->Wanted(channel)) continue;
    const TactileFrame& reading = readings.Pad(pad);
    std::vector<float> normal(reading.forces.size());
    for (size_t i = 0; i < normal.size(); ++i) normal[i] = static_cast<float>(std::max(0.0, -reading.forces[i].z()));
    writer_->Write(channel, time_ns, ros2::EncodeFloat32MultiArray(reading.rows, reading.cols, normal));
  }

  for (const std::string& joint_id : force_torque_joints_) {
    const auto found = model.joint_index.find(joint_id);
    if (found == model.joint_index.end()) continue;  // removed since the recording started
    const uint32_t channel = Channel("/wrench/" + joint_id, ros2::kWrenchStamped.name);
    if (!writer_->Wanted(channel)) continue;
    const ForceTorqueReading reading = ReadForceTorque(model, state, found->second);
    const std::string& child = model.bodies[model.joint_bodies[found->second][1]].id;
    writer_->Write(channel, time_ns, ros2::EncodeWrenchStamped(stamp, child, reading.force, reading.torque));
  }
}

void Ros2Channels::WritePointCloud(const std::string& topic, double time, const std::vector<Vec3>& points) {
  const uint32_t channel = Channel(topic, ros2::kPointCloud2.name);
  if (!writer_->Wanted(channel)) return;
  const uint64_t time_ns = static_cast<uint64_t>(std::llround(std::max(0.0, time) * 1e9));
  writer_->Write(channel, time_ns, ros2::EncodePointCloud2(ros2::StampOf(time), "world", points));
}

}  // namespace graspsim::recording
