// The recordings of one server (RecordingService, docs/recording.md): at most one active recording per scene,
// each a RecordingSession fed by a FrameTap, all files in one directory under plain names (a request can neither
// read nor write outside it), the figures of the recordings this server finished, and the automatic recording
// of every scene (--record). A recording whose scene was deleted ends by itself and is reaped on the next call.
#pragma once

#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "recording/frame_tap.h"
#include "recording/mcap_writer.h"
#include "recording/recording_session.h"
#include "world/scene.h"

namespace graspsim::recording {

// What RecordingService reports of a recording.
struct RecordingInfo {
  std::string name, scene_id, path, ros2_path;
  bool active = false;
  uint64_t frames = 0, dropped_frames = 0, messages = 0, bytes = 0;
  double start_time = 0, end_time = 0;  // s, simulated
};

// A StartRecording request, decoded.
struct RecordingRequest {
  std::string name;            // "" = "<scene id>-<UTC time>.mcap"
  bool ros2 = true;            // a ROS 2 bag beside the file ("<name without .mcap>.ros2")
  Compression compression = Compression::kZstd;
  std::vector<std::string> force_torque_joints;  // joints of the scene
  double rate_hz = 0;          // frames per simulated second, (0, 1000]; 0 = 30
};

class Recorders {
 public:
  // `directory`: where recordings are written and read, created when missing ("" = recordings are off).
  explicit Recorders(std::string directory);
  ~Recorders();  // StopAll

  // Starts recording `scene` with the file's channels from `encoder`. Errors: kFailedPrecondition when
  // recordings are off or a file cannot be created, kInvalidArgument for a bad name (PathOf) or rate_hz,
  // kNotFound for a force_torque_joints entry the scene lacks, kAlreadyExists when the scene is being recorded
  // or the name (or its bag) exists.
  RecordingInfo Start(const std::shared_ptr<Scene>& scene, const RecordingRequest& request,
                      const FrameEncoderFactory& encoder);
  // --record: Start with the defaults; an error is logged, not thrown.
  void StartAutomatically(const std::shared_ptr<Scene>& scene, const FrameEncoderFactory& encoder);
  // Finishes the scene's recording (its files complete) and returns its figures. kNotFound when the scene is not
  // being recorded; kInternal when the recording failed (its figures are kept for List even so).
  RecordingInfo Stop(const std::string& scene_id);
  // Finishes every recording (server shutdown).
  void StopAll();
  // The active recordings (by scene id), then every other .mcap file of the directory by name: those this
  // server finished with their figures, older ones with their name, path and size.
  std::vector<RecordingInfo> List();

  // The path of recording `name` (letters, digits, '-', '_', '.', ending in .mcap: kInvalidArgument naming
  // `field` otherwise; kFailedPrecondition when recordings are off).
  std::string PathOf(const std::string& field, const std::string& name) const;
  // The scene whose active recording writes `name` ("" when none does).
  std::string ActiveSceneOf(const std::string& name);
  // Runs `use` on the scene's active session, kept alive meanwhile; false (and `use` not run) when none.
  bool WithSession(const std::string& scene_id, const std::function<void(RecordingSession&)>& use);

 private:
  struct Active;
  void ReapLocked();  // caller holds mutex_

  const std::string directory_;
  std::mutex mutex_;
  std::map<std::string, std::shared_ptr<Active>> active_;  // by scene id
  std::map<std::string, RecordingInfo> finished_;          // by name: recordings this server finished
};

}  // namespace graspsim::recording
