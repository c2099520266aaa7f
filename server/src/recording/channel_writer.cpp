#include "recording/channel_writer.h"

namespace graspsim::recording {

const TactileFrame& FrameReadings::Pad(size_t pad) {
  auto it = pads_.find(pad);
  if (it == pads_.end()) it = pads_.emplace(pad, ReadTactileArray(*frame_.model, *frame_.state, pad)).first;
  return it->second;
}

uint32_t McapChannelWriter::AddChannel(const ChannelSpec& spec) {
  auto [it, added] = schemas_.try_emplace(spec.schema_name, 0);
  if (added) it->second = file_->AddSchema(spec.schema_name, spec.schema_encoding, spec.schema_data);
  return file_->AddChannel(it->second, spec.topic, spec.message_encoding);
}

void McapChannelWriter::Write(uint32_t channel, uint64_t time_ns, std::string_view payload) {
  file_->Write(static_cast<uint16_t>(channel), time_ns, time_ns, payload);
}

}  // namespace graspsim::recording
