// graspsim.v1.RecordingService (docs/recording.md): recordings of scenes as MCAP files, their download, and their
// replay into new scenes. The recordings and replays themselves are recording/recorders.h and replays.h; this
// service decodes, calls and encodes, and gives each recording its protobuf channels (recording_channels.h).
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "core/worker_pool.h"
#include "graspsim/v1/recording.grpc.pb.h"
#include "recording/recorders.h"
#include "recording/replays.h"
#include "rpc/recording_log.h"
#include "world/scene_registry.h"

namespace graspsim::rpc {

class RecordingServiceImpl final : public v1::RecordingService::CallbackService, public RecordingLog {
 public:
  // `directory`: where recordings are written and read ("" = recordings are off: FAILED_PRECONDITION).
  RecordingServiceImpl(SceneRegistry* registry, WorkerPool* pool, std::string directory);

  // --record: records `scene` from now on under "<scene id>-<UTC time>.mcap" (every group, zstd).
  void RecordAutomatically(const std::shared_ptr<Scene>& scene);
  // Finishes every recording (server shutdown): their files are complete.
  void StopAll() { recorders_.StopAll(); }
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
  // How replays read the graspsim channels and apply their edits (recording_replay.cpp).
  recording::ReplayCodec ReplayCodecOf();

  SceneRegistry* registry_;
  WorkerPool* pool_;
  recording::Recorders recorders_;
  recording::Replays replays_;
};

}  // namespace graspsim::rpc
