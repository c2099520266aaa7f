#include "recording/ros2_bag.h"

#include <cstring>
#include <filesystem>
#include <fstream>

#include "core/durable_files.h"
#include "core/error.h"

namespace graspsim::recording {
namespace {

std::string FileNameOf(const std::string& directory) {
  return std::filesystem::path(directory).filename().string() + "_0.mcap";
}

}  // namespace

Ros2Bag::Ros2Bag(const std::string& directory, Compression compression)
    : directory_(directory), file_name_(FileNameOf(directory)), channels_(nullptr) {
  std::error_code error;
  if (!std::filesystem::create_directory(directory, error)) {
    throw Error(ErrorCode::kFailedPrecondition,
                "cannot create the ROS 2 bag directory '" + directory + "': " +
                    (error ? error.message() : std::string("it exists")));
  }
  file_ = std::make_unique<McapWriter>(directory + "/" + file_name_, McapOptions{"ros2", compression});
  channels_ = McapChannelWriter(file_.get());
  WriteMetadata();
}

Ros2Bag::~Ros2Bag() {
  try {
    Close();
  } catch (const Error&) {
  }
}

uint32_t Ros2Bag::AddChannel(const ChannelSpec& spec) {
  const uint32_t id = channels_.AddChannel(spec);
  topics_[id] = {spec.topic, spec.schema_name, 0};
  WriteMetadata();
  return id;
}

void Ros2Bag::Write(uint32_t channel, uint64_t time_ns, std::string_view payload) {
  channels_.Write(channel, time_ns, payload);
  ++topics_[channel].count;
  ++count_;
  first_time_ = std::min(first_time_, time_ns);
  last_time_ = std::max(last_time_, time_ns);
}

void Ros2Bag::Close() {
  if (!file_) return;
  file_->Close();
  closed_bytes_ = file_->bytes_written();
  file_.reset();
  WriteMetadata(/*durable=*/true);
  // The bag directory's own name, in the recording directory.
  if (!SyncDirectory(std::filesystem::absolute(directory_).parent_path())) {
    throw Error(ErrorCode::kInternal, "cannot sync the directory of '" + directory_ + "'");
  }
}

uint64_t Ros2Bag::bytes_written() const { return file_ ? file_->bytes_written() : closed_bytes_; }

void Ros2Bag::WriteMetadata(bool durable) const {
  // Version 5 of rosbag2's metadata: the fields every reader since Foxy/Humble expects. Written to a temporary
  // file and renamed, so a reader never sees half of it.
  const uint64_t start = count_ ? first_time_ : 0, duration = count_ ? last_time_ - first_time_ : 0;
  std::string yaml = "rosbag2_bagfile_information:\n  version: 5\n  storage_identifier: mcap\n";
  yaml += "  duration:\n    nanoseconds: " + std::to_string(duration) + "\n";
  yaml += "  starting_time:\n    nanoseconds_since_epoch: " + std::to_string(start) + "\n";
  yaml += "  message_count: " + std::to_string(count_) + "\n  topics_with_message_count:" +
          (topics_.empty() ? " []\n" : "\n");
  for (const auto& [id, topic] : topics_) {
    yaml += "    - topic_metadata:\n        name: \"" + topic.name + "\"\n        type: " + topic.type +
            "\n        serialization_format: cdr\n        offered_qos_profiles: \"\"\n      message_count: " +
            std::to_string(topic.count) + "\n";
  }
  yaml += "  compression_format: \"\"\n  compression_mode: \"\"\n  relative_file_paths:\n    - " + file_name_ +
          "\n  files:\n    - path: " + file_name_ + "\n      starting_time:\n        nanoseconds_since_epoch: " +
          std::to_string(start) + "\n      duration:\n        nanoseconds: " + std::to_string(duration) +
          "\n      message_count: " + std::to_string(count_) + "\n";
  const std::string path = directory_ + "/metadata.yaml";
  if (durable) {
    ReplaceFileDurably(path, yaml);
    return;
  }
  {
    std::ofstream out(path + ".tmp", std::ios::binary | std::ios::trunc);
    out << yaml;
    if (!out) throw Error(ErrorCode::kInternal, "cannot write '" + path + "'");
  }
  std::filesystem::rename(path + ".tmp", path);
}

}  // namespace graspsim::recording
