// A scene's frames as protobuf channels (docs/recording.md): graspsim's own ("/graspsim/*": the API's messages,
// enough to rebuild and replay the scene) and Foxglove's ("/tf", "/scene", "/tactile/<array>", "/log": a 3D
// scene, transforms, tactile images and a log that Foxglove shows with no plug-in). Used by recordings (MCAP)
// and by the live Foxglove endpoint, so both carry the same channels.
#pragma once

#include <map>
#include <memory>
#include <string>
#include <vector>

#include "recording/channel_writer.h"
#include "recording/recording_session.h"
#include "world/scene.h"

namespace google::protobuf {
class Message;
}

namespace graspsim::rpc {

struct ChannelGroups {
  bool graspsim = true, foxglove = true, ros2 = true;
};
// "graspsim", "foxglove", "ros2"; none: all. Throws Error(kInvalidArgument) naming `field` and the value.
ChannelGroups ParseChannelGroups(const std::string& field, const std::vector<std::string>& names);

class ProtobufChannels : public recording::FrameEncoder {
 public:
  ProtobufChannels(recording::ChannelWriter* writer, ChannelGroups groups, std::vector<std::string> force_torque_joints);
  ~ProtobufChannels() override;
  // One frame (carrying its model, state and edits): edits not written yet go first. `readings`: its tactile
  // frames, shared with the other encoders of the frame.
  void Write(const SceneSnapshot& frame, recording::FrameReadings& readings) override;
  // Any API message on a graspsim channel of its own (graspsim group): a real gripper's action beside its twin.
  void WriteMessage(const std::string& topic, double time, const google::protobuf::Message& message);
  // A point cloud in the world frame as foxglove.PointCloud (foxglove group): float32 x y z, 12 bytes a point.
  void WritePointCloud(const std::string& topic, double time, const std::vector<Vec3>& points) override;
  // A line on "/log" (foxglove group).
  void Log(double time, int level, const std::string& message) override;

 private:
  struct Channels;
  std::unique_ptr<Channels> channels_;
};

}  // namespace graspsim::rpc
