// A ROS 2 bag directory (rosbag2 format, storage "mcap"): metadata.yaml, which rosbag2 and rosbags read first,
// and one MCAP file of CDR messages with the profile "ros2". metadata.yaml is rewritten when a topic is added and
// at Close, so a bag whose writer was killed still opens (with the counts of its last rewrite).
#pragma once

#include <map>
#include <memory>
#include <string>
#include <vector>

#include "recording/channel_writer.h"

namespace graspsim::recording {

class Ros2Bag : public ChannelWriter {
 public:
  // Creates `directory` (it must not exist); throws Error(kFailedPrecondition) naming it when it cannot.
  Ros2Bag(const std::string& directory, Compression compression);
  ~Ros2Bag() override;
  uint32_t AddChannel(const ChannelSpec& spec) override;
  void Write(uint32_t channel, uint64_t time_ns, std::string_view payload) override;
  void Flush() { if (file_) file_->Flush(); }
  void Close();
  uint64_t bytes_written() const;

 private:
  struct Topic {
    std::string name, type;
    uint64_t count = 0;
  };
  // `durable`: synced to the disk (the last one, at Close); the ones before are for readers of a bag in progress.
  void WriteMetadata(bool durable = false) const;

  std::string directory_, file_name_;
  std::unique_ptr<McapWriter> file_;
  McapChannelWriter channels_;
  std::map<uint32_t, Topic> topics_;
  uint64_t first_time_ = UINT64_MAX, last_time_ = 0, count_ = 0, closed_bytes_ = 0;
};

}  // namespace graspsim::recording
