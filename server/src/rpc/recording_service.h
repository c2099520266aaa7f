// graspsim.v1.RecordingService (docs/recording.md): recordings of scenes as MCAP files (recording_session.h),
// their download, and their replay into new scenes. Recording files live in one directory; names are plain file
// names, so a request can neither read nor write outside it.
#pragma once

#include <filesystem>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "core/worker_pool.h"
#include "graspsim/v1/recording.grpc.pb.h"
#include "recording/frame_tap.h"
#include "rpc/recording_log.h"
#include "world/scene_registry.h"

namespace graspsim::rpc {

class RecordingServiceImpl final : public v1::RecordingService::CallbackService, public RecordingLog {
 public:
  // `directory`: where recordings are written and read ("" = recordings are off: FAILED_PRECONDITION).
  RecordingServiceImpl(SceneRegistry* registry, WorkerPool* pool, std::string directory);
  ~RecordingServiceImpl() override;

  // --record: records `scene` from now on under "<scene id>-<UTC time>.mcap" (every group, zstd).
  void RecordAutomatically(const std::shared_ptr<Scene>& scene);
  // Finishes every recording (server shutdown): their files are complete.
  void StopAll();
  void Append(const std::string& scene_id, const std::string& topic, const google::protobuf::Message& message) override;
  void AppendPointCloud(const std::string& scene_id, const std::string& topic,
                        const std::vector<Vec3>& points) override;

  using Context = grpc::CallbackServerContext;
  using Unary = grpc::ServerUnaryReactor;
  Unary* StartRecording(Context*, const v1::StartRecordingRequest*, v1::Recording*) override;
  Unary* StopRecording(Context*, const v1::StopRecordingRequest*, v1::Recording*) override;
  Unary* ListRecordings(Context*, const v1::ListRecordingsRequest*, v1::ListRecordingsResponse*) override;
  grpc::ServerWriteReactor<v1::RecordingChunk>* DownloadRecording(Context*, const v1::DownloadRecordingRequest*) override;
  Unary* ReplayRecording(Context*, const v1::ReplayRecordingRequest*, v1::ReplayRecordingResponse*) override;
  Unary* SeekReplay(Context*, const v1::SeekReplayRequest*, v1::SeekReplayResponse*) override;

 private:
  struct Active;
  // A recording read for replay: its edits, and per frame the state and how many edits its model needs.
  struct Replay {
    std::vector<SceneOp> edits;
    std::vector<std::string> states;  // persistence::EncodeState bytes
    std::vector<double> times;
    std::vector<uint64_t> edit_counts;
    std::pair<std::filesystem::file_time_type, uintmax_t> stamp;  // of the file read: a file replaced is read again
  };
  void Start(const std::shared_ptr<Scene>& scene, const v1::StartRecordingRequest& request, v1::Recording* out);
  std::string PathOf(const std::string& field, const std::string& name) const;
  std::shared_ptr<const Replay> LoadReplay(const std::string& name);
  // Caller holds mutex_. Recordings whose scene was deleted end by themselves: move them to finished_.
  void ReapLocked();
  // Caller holds mutex_. The scene whose recording is writing the file `name` ("" when none is).
  std::string ActiveSceneOfLocked(const std::string& name);
  // The active recording of a scene, or null.
  std::shared_ptr<Active> ActiveOf(const std::string& scene_id);
  // Applies the edits a frame needs to a replayed scene and then its state.
  uint64_t SeekLocked(Scene* scene, const std::string& name, const Replay& replay, size_t frame);

  SceneRegistry* registry_;
  WorkerPool* pool_;
  const std::string directory_;
  std::mutex mutex_;
  std::map<std::string, std::shared_ptr<Active>> active_;  // by scene id
  std::map<std::string, v1::Recording> finished_;          // by name: recordings this server finished
  struct ReplayedScene {
    std::string name;    // the recording
    size_t edits = 0;    // of its edits applied
  };
  std::map<std::string, ReplayedScene> replayed_;          // by scene id: scenes made by ReplayRecording
  std::map<std::string, std::shared_ptr<const Replay>> replays_;  // by recording name, the last few loaded
  std::vector<std::string> replay_order_;
};

}  // namespace graspsim::rpc
