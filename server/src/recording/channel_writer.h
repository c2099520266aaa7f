// Where encoded messages go: an MCAP file (McapChannelWriter), a ROS 2 bag (ros2_bag.h) or a live Foxglove
// connection (rpc/foxglove_live.cpp). Encoders add their channels once and write payloads to them.
#pragma once

#include <cstdint>
#include <map>
#include <string>
#include <string_view>

#include "recording/mcap_writer.h"
#include "tactile/tactile_frame.h"
#include "world/snapshot_hub.h"

namespace graspsim::recording {

struct ChannelSpec {
  std::string topic;
  std::string message_encoding;  // "protobuf", "cdr"
  std::string schema_name;       // "foxglove.FrameTransforms", "tf2_msgs/msg/TFMessage"
  std::string schema_encoding;   // "protobuf", "ros2msg"
  std::string schema_data;       // a serialized FileDescriptorSet, or ros2msg text
};

class ChannelWriter {
 public:
  virtual ~ChannelWriter() = default;
  virtual uint32_t AddChannel(const ChannelSpec& spec) = 0;
  // False when nobody reads the channel (a live client not subscribed to it): the encoder skips the work.
  virtual bool Wanted(uint32_t /*channel*/) const { return true; }
  virtual void Write(uint32_t channel, uint64_t time_ns, std::string_view payload) = 0;
};

// The tactile frames of one frame, read once for every encoder of it (each array's read transforms every
// texel's force into the pad frame: the largest share of a recording's CPU when each encoder read them again).
class FrameReadings {
 public:
  explicit FrameReadings(const SceneSnapshot& frame) : frame_(frame) {}
  const TactileFrame& Pad(size_t pad);

 private:
  const SceneSnapshot& frame_;
  std::map<size_t, TactileFrame> pads_;
};

// Channels of one MCAP file; a schema shared by several channels is written once.
class McapChannelWriter : public ChannelWriter {
 public:
  explicit McapChannelWriter(McapWriter* file) : file_(file) {}
  uint32_t AddChannel(const ChannelSpec& spec) override;
  void Write(uint32_t channel, uint64_t time_ns, std::string_view payload) override;

 private:
  McapWriter* file_;
  std::map<std::string, uint16_t> schemas_;  // by name
};

}  // namespace graspsim::recording
