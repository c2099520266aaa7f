// ROS 2 messages in their wire encoding (CDR, little endian, XCDR1 as rosbag2 stores it) with their ros2msg
// definitions (the text rosbag2 writes as an MCAP schema: the message, then each type it uses after a line of
// '=' and "MSG: <type>"). Only the types a graspsim recording writes; written to the ROS 2 interface definitions
// (common_interfaces), since no ROS 2 package is in our registries.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "core/math.h"

namespace graspsim::recording::ros2 {

struct MessageType {
  const char* name;        // "tf2_msgs/msg/TFMessage"
  const char* definition;  // ros2msg text
};
extern const MessageType kTFMessage, kJointState, kFloat32MultiArray, kWrenchStamped, kPointCloud2;

struct Stamp {
  int32_t sec = 0;
  uint32_t nanosec = 0;
};
Stamp StampOf(double seconds);

struct Transform {
  std::string parent, child;
  Pose pose;
};
std::string EncodeTFMessage(const Stamp& stamp, const std::vector<Transform>& transforms);
std::string EncodeJointState(const Stamp& stamp, const std::vector<std::string>& names,
                             const std::vector<double>& positions, const std::vector<double>& velocities,
                             const std::vector<double>& efforts);
// A row-major rows × cols array: dims "rows" and "cols".
std::string EncodeFloat32MultiArray(unsigned rows, unsigned cols, const std::vector<float>& data);
// An unorganized cloud (height 1): fields x, y, z as float32, 12 bytes per point, little endian, dense.
std::string EncodePointCloud2(const Stamp& stamp, const std::string& frame_id, const std::vector<Vec3>& points);
std::string EncodeWrenchStamped(const Stamp& stamp, const std::string& frame_id, const Vec3& force,
                                const Vec3& torque);

}  // namespace graspsim::recording::ros2
