// A scene's frames as ROS 2 messages: /tf (tf2_msgs/TFMessage: every body in the world frame), /joint_states
// (sensor_msgs/JointState: every moving joint), /tactile/<array> (std_msgs/Float32MultiArray: rows × cols normal
// forces, N) and /wrench/<joint> (geometry_msgs/WrenchStamped: the F/T reading of each joint asked for).
// Channels are added as the model brings them (a pad added mid-recording gets its topic then).
#pragma once

#include <map>
#include <string>
#include <vector>

#include "core/math.h"
#include "recording/channel_writer.h"
#include "world/snapshot_hub.h"

namespace graspsim::recording {

class Ros2Channels {
 public:
  Ros2Channels(ChannelWriter* writer, std::vector<std::string> force_torque_joints)
      : writer_(writer), force_torque_joints_(std::move(force_torque_joints)) {}
  // `frame` carries its model and state; `readings` are its tactile frames.
  void Write(const SceneSnapshot& frame, FrameReadings& readings);
  // A point cloud in the world frame (sensor_msgs/PointCloud2), e.g. what a shape completion saw.
  void WritePointCloud(const std::string& topic, double time, const std::vector<Vec3>& points);

 private:
  uint32_t Channel(const std::string& topic, const char* type_name);

  ChannelWriter* writer_;
  std::vector<std::string> force_torque_joints_;
  std::map<std::string, uint32_t> channels_;  // by topic
};

}  // namespace graspsim::recording
