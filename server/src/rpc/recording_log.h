// Messages that are not scene states but belong in a scene's recording: a real gripper's action and its
// predicted and measured readings with their surprise (GatewayService.PredictAction), so that a real robot's
// session can be replayed beside its simulated twin. Implemented by RecordingServiceImpl.
#pragma once

#include <string>

namespace google::protobuf {
class Message;
}

namespace graspsim::rpc {

class RecordingLog {
 public:
  virtual ~RecordingLog() = default;
  // Adds `message` on `topic` of the scene's recording, at the time of its last frame; nothing when the scene
  // is not being recorded. Never throws: a recording that cannot take it does not fail the caller.
  virtual void Append(const std::string& scene_id, const std::string& topic,
                      const google::protobuf::Message& message) = 0;
};

}  // namespace graspsim::rpc
