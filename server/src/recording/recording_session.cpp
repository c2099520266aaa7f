#include "recording/recording_session.h"

namespace graspsim::recording {
namespace {

constexpr auto kFlushInterval = std::chrono::seconds(1);

}  // namespace

RecordingSession::RecordingSession(const SessionOptions& options, double start_time, const FrameEncoderFactory& encoder)
    : file_(std::make_unique<McapWriter>(options.path, McapOptions{"", options.compression})),
      file_channels_(file_.get()),
      channels_(encoder(&file_channels_)),
      last_time_(start_time) {
  if (!options.ros2_path.empty()) {
    bag_ = std::make_unique<Ros2Bag>(options.ros2_path, options.compression);
    ros2_ = std::make_unique<Ros2Channels>(bag_.get(), options.force_torque_joints);
  }
}

void RecordingSession::Consume(const SceneSnapshot& frame) {
  std::lock_guard<std::mutex> lock(mutex_);
  const double time = frame.state->time;
  if (first_) {
    first_ = false;
    start_time_ = time;
    channels_->Log(time, 2, "recording started at t = " + std::to_string(time) + " s");
  }
  last_time_ = time;
  end_time_ = time;
  FrameReadings readings(frame);
  channels_->Write(frame, readings);
  if (ros2_) ros2_->Write(frame, readings);
  const auto now = std::chrono::steady_clock::now();
  if (now - last_flush_ >= kFlushInterval) {
    file_->Flush();
    if (bag_) bag_->Flush();
    last_flush_ = now;
  }
  Publish();
}

void RecordingSession::Append(const std::function<void(FrameEncoder& encoder, double time)>& write) {
  std::lock_guard<std::mutex> lock(mutex_);
  if (finished_) return;
  write(*channels_, last_time_);
  Publish();
}

void RecordingSession::AppendPointCloud(const std::string& topic, const std::vector<Vec3>& points) {
  std::lock_guard<std::mutex> lock(mutex_);
  if (finished_) return;
  channels_->WritePointCloud(topic, last_time_, points);
  if (ros2_) ros2_->WritePointCloud(topic, last_time_, points);
  Publish();
}

void RecordingSession::Finish() {
  std::lock_guard<std::mutex> lock(mutex_);
  finished_ = true;
  if (!first_) channels_->Log(last_time_, 2, "recording stopped at t = " + std::to_string(last_time_) + " s");
  if (bag_) bag_->Close();
  file_->Close();
  Publish();
}

void RecordingSession::Publish() {
  messages_ = file_->message_count();
  bytes_ = file_->bytes_written();
}

}  // namespace graspsim::recording
