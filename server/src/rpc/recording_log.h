// Messages that are not scene states but belong in a scene's recording: a real gripper's action and its
// predicted and measured readings with their surprise (GatewayService.PredictAction), so that a real robot's
// session can be replayed beside its simulated twin; the points a shape completion added to the scene saw. Implemented by RecordingServiceImpl.
#pragma once

#include <string>
#include <vector>

#include "core/math.h"

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
  // A point cloud in the world frame (what a shape completion saw): foxglove.PointCloud in the recording and
  // sensor_msgs/PointCloud2 in its ROS 2 bag, on `topic`. The same rules as Append.
  virtual void AppendPointCloud(const std::string& scene_id, const std::string& topic,
                                const std::vector<Vec3>& points) = 0;
};

}  // namespace graspsim::rpc
