// One recording: a scene's frames into an MCAP file and, when asked, a ROS 2 bag directory beside it. Fed by a
// FrameTap on its own thread; chunks are written out as they fill and at least once a second, so a server killed
// mid-run leaves every earlier second readable. The file's graspsim and Foxglove channels are protobuf, encoded
// above this library (rpc/recording_channels.h) behind FrameEncoder; the bag's ROS 2 channels are encoded here.
#pragma once

#include <atomic>
#include <chrono>
#include <functional>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "recording/channel_writer.h"
#include "recording/frame_tap.h"
#include "recording/mcap_writer.h"
#include "recording/ros2_bag.h"
#include "recording/ros2_channels.h"

namespace graspsim::recording {

// The channels of the MCAP file that this library does not encode itself.
class FrameEncoder {
 public:
  virtual ~FrameEncoder() = default;
  // One frame (with its model, state and edits); `readings` are its tactile frames, shared with the bag.
  virtual void Write(const SceneSnapshot& frame, FrameReadings& readings) = 0;
  // A point cloud in the world frame, e.g. what a shape completion saw.
  virtual void WritePointCloud(const std::string& topic, double time, const std::vector<Vec3>& points) = 0;
  // A line of the recording's log (level as foxglove.Log's: 2 = info).
  virtual void Log(double time, int level, const std::string& message) = 0;
};
// Makes the encoder of a session's file.
using FrameEncoderFactory = std::function<std::unique_ptr<FrameEncoder>(ChannelWriter* file)>;

struct SessionOptions {
  std::string path;       // the .mcap file
  std::string ros2_path;  // the bag directory; empty = no bag
  Compression compression = Compression::kZstd;
  std::vector<std::string> force_torque_joints;  // the bag's /wrench/<joint> topics
};

class RecordingSession : public FrameConsumer {
 public:
  // Creates the files (Error(kFailedPrecondition) naming a path that cannot be created). `start_time`: the
  // scene's simulated time now (Append's time until the first frame).
  RecordingSession(const SessionOptions& options, double start_time, const FrameEncoderFactory& encoder);
  void Consume(const SceneSnapshot& frame) override;
  void Finish() override;
  // Anything else for the file from another part of the server, at the time of the last frame: `write` gets the
  // encoder and that time, under the session's lock. Thread-safe; nothing once the session finished.
  void Append(const std::function<void(FrameEncoder& encoder, double time)>& write);
  // A point cloud in the world frame, into the file (the encoder's) and the bag.
  void AppendPointCloud(const std::string& topic, const std::vector<Vec3>& points);

  uint64_t messages() const { return messages_.load(); }
  uint64_t bytes() const { return bytes_.load(); }  // of the .mcap file
  double start_time() const { return start_time_.load(); }
  double end_time() const { return end_time_.load(); }

 private:
  void Publish();

  std::unique_ptr<McapWriter> file_;
  McapChannelWriter file_channels_;
  std::unique_ptr<FrameEncoder> channels_;
  std::unique_ptr<Ros2Bag> bag_;
  std::unique_ptr<Ros2Channels> ros2_;
  std::mutex mutex_;  // the files: frames come from the tap's thread, Append from any
  bool first_ = true, finished_ = false;
  double last_time_ = 0;
  std::chrono::steady_clock::time_point last_flush_ = std::chrono::steady_clock::now();
  std::atomic<uint64_t> messages_{0}, bytes_{0};
  std::atomic<double> start_time_{0}, end_time_{0};
};

}  // namespace graspsim::recording
