// One recording: a scene's frames into an MCAP file (graspsim and Foxglove channels) and, with the "ros2" group,
// a ROS 2 bag directory beside it. Fed by a recording::FrameTap on its own thread; chunks are written out as they
// fill and at least once a second, so a server killed mid-run leaves every earlier second readable.
#pragma once

#include <atomic>
#include <chrono>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "recording/frame_tap.h"
#include "recording/mcap_writer.h"
#include "recording/ros2_bag.h"
#include "recording/ros2_channels.h"
#include "rpc/recording_channels.h"

namespace graspsim::rpc {

struct RecordingOptions {
  std::string path;       // the .mcap file
  std::string ros2_path;  // the bag directory; empty without the ros2 group
  ChannelGroups groups;
  recording::Compression compression = recording::Compression::kZstd;
  std::vector<std::string> force_torque_joints;
  double interval = 1.0 / 30;  // simulated s between frames (FrameTap)
};

class RecordingSession : public recording::FrameConsumer {
 public:
  // Creates the files (Error(kFailedPrecondition) naming a path that cannot be created). `start_time`: the
  // scene's simulated time now (Append's time until the first frame).
  RecordingSession(const RecordingOptions& options, double start_time);
  void Consume(const SceneSnapshot& frame) override;
  void Finish() override;
  // A message from another part of the server (recording_log.h), at the time of the last frame; thread-safe.
  void Append(const std::string& topic, const google::protobuf::Message& message);
  void AppendPointCloud(const std::string& topic, const std::vector<Vec3>& points);

  uint64_t messages() const { return messages_.load(); }
  uint64_t bytes() const { return bytes_.load(); }  // of the .mcap file
  double start_time() const { return start_time_.load(); }
  double end_time() const { return end_time_.load(); }

 private:
  void Publish();

  std::unique_ptr<recording::McapWriter> file_;
  recording::McapChannelWriter file_channels_;
  ProtobufChannels channels_;
  std::unique_ptr<recording::Ros2Bag> bag_;
  std::unique_ptr<recording::Ros2Channels> ros2_;
  std::mutex mutex_;  // the files: frames come from the tap's thread, Append from any
  bool first_ = true, finished_ = false;
  double last_time_ = 0;
  std::chrono::steady_clock::time_point last_flush_ = std::chrono::steady_clock::now();
  std::atomic<uint64_t> messages_{0}, bytes_{0};
  std::atomic<double> start_time_{0}, end_time_{0};
};

}  // namespace graspsim::rpc
