#include "rpc/recording_service.h"

#include "edits/scene_restore.h"
#include "persistence/state_codec.h"
#include "rpc/call.h"
#include "rpc/scene_edits.h"

// RecordingService's replay (recording/replays.h): how a recording's graspsim channels are read (the API's
// RecordedEdit and RecordedState messages) and its edits applied (through the RPCs' own code), and the two calls.
namespace graspsim::rpc {

recording::ReplayCodec RecordingServiceImpl::ReplayCodecOf() {
  recording::ReplayCodec codec;
  codec.edit = [](const std::string& name, std::string_view message) {
    v1::RecordedEdit edit;
    if (!edit.ParseFromArray(message.data(), static_cast<int>(message.size()))) {
      throw Error(ErrorCode::kFailedPrecondition, "recording '" + name + "': an edit does not parse");
    }
    SceneOp op{edit.kind(), edit.request(), edit.path(), edit.sha256(), nullptr};
    if (edit.kind() == "UploadFile") op.file = std::make_shared<const std::string>(edit.file());
    return op;
  };
  codec.frame = [](const std::string& name, std::string_view message) {
    v1::RecordedState state;
    if (!state.ParseFromArray(message.data(), static_cast<int>(message.size()))) {
      throw Error(ErrorCode::kFailedPrecondition, "recording '" + name + "': a state does not parse");
    }
    return recording::RecordedFrame{state.time(), state.state(), state.edits()};
  };
  codec.decode_state = [](const std::string& state, const std::string& what) {
    return persistence::DecodeState(state, what);
  };
  codec.apply_edit = [this](Scene* scene, const SceneOp& edit) {
    edits::ReplayEdit(scene, edit, registry_->limits(), LegacyEditReaderFor(registry_->limits()));
  };
  return codec;
}

grpc::ServerUnaryReactor* RecordingServiceImpl::ReplayRecording(Context* context,
                                                                const v1::ReplayRecordingRequest* request,
                                                                v1::ReplayRecordingResponse* response) {
  return RunUnary(context, "RecordingService/ReplayRecording", pool_, [=, this] {
    const recording::Replays::Started started = replays_.Start(request->name(), request->scene_name());
    response->set_scene_id(started.scene->id());
    response->set_frames(started.replay->frames.size());
    for (const recording::RecordedFrame& frame : started.replay->frames) response->add_frame_times(frame.time);
  });
}

grpc::ServerUnaryReactor* RecordingServiceImpl::SeekReplay(Context* context, const v1::SeekReplayRequest* request,
                                                           v1::SeekReplayResponse* response) {
  return RunUnary(context, "RecordingService/SeekReplay", pool_, [=, this] {
    const recording::Replays::Sought sought = replays_.Seek(request->scene_id(), request->name(), request->frame());
    response->set_revision(sought.revision);
    response->set_time(sought.time);
  });
}

}  // namespace graspsim::rpc
