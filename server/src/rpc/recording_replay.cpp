#include "rpc/recording_service.h"

#include <algorithm>
#include <filesystem>

#include "persistence/state_codec.h"
#include "recording/mcap_reader.h"
#include "rpc/call.h"
#include "rpc/scene_replay.h"

// RecordingService's replay: a recording read into memory (its edits and states), a new scene built from it, and
// seeks within it.
namespace graspsim::rpc {
namespace {

namespace fs = std::filesystem;
constexpr size_t kReplaysKept = 4;  // recordings kept in memory after a replay or seek

}  // namespace

std::shared_ptr<const RecordingServiceImpl::Replay> RecordingServiceImpl::LoadReplay(const std::string& name) {
  const std::string path = PathOf("name", name);
  {
    std::lock_guard<std::mutex> lock(mutex_);
    const std::string recording_scene = ActiveSceneOfLocked(name);
    if (!recording_scene.empty()) {
      throw Error(ErrorCode::kFailedPrecondition, "name: recording '" + name + "' of scene '" + recording_scene +
                                                      "' is still being written; stop it first");
    }
  }
  std::error_code error;
  const auto stamp = std::make_pair(fs::last_write_time(path, error), fs::file_size(path, error));
  if (error) ThrowNotFound("name: no recording '" + name + "'");
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (auto it = replays_.find(name); it != replays_.end() && it->second->stamp == stamp) return it->second;
  }
  auto replay = std::make_shared<Replay>();
  replay->stamp = stamp;
  recording::ReadMcap(path, name, [&](const recording::McapMessage& message) {
    if (message.topic == "/graspsim/edit") {
      v1::RecordedEdit edit;
      if (!edit.ParseFromArray(message.data.data(), static_cast<int>(message.data.size()))) {
        throw Error(ErrorCode::kFailedPrecondition, "recording '" + name + "': an edit does not parse");
      }
      SceneOp op{edit.kind(), edit.request(), edit.path(), edit.sha256(), nullptr};
      if (edit.kind() == "UploadFile") op.file = std::make_shared<const std::string>(edit.file());
      replay->edits.push_back(std::move(op));
    } else if (message.topic == "/graspsim/state") {
      v1::RecordedState state;
      if (!state.ParseFromArray(message.data.data(), static_cast<int>(message.data.size()))) {
        throw Error(ErrorCode::kFailedPrecondition, "recording '" + name + "': a state does not parse");
      }
      if (state.edits() > replay->edits.size()) {
        throw Error(ErrorCode::kFailedPrecondition, "recording '" + name + "': a state needs edits not recorded");
      }
      replay->times.push_back(state.time());
      replay->states.push_back(state.state());
      replay->edit_counts.push_back(state.edits());
    }
  });
  if (replay->states.empty()) {
    throw Error(ErrorCode::kFailedPrecondition,
                "name: recording '" + name + "' has no /graspsim/state frames (recorded without the graspsim group?)");
  }
  std::lock_guard<std::mutex> lock(mutex_);
  if (replays_.count(name)) replay_order_.erase(std::find(replay_order_.begin(), replay_order_.end(), name));
  replays_[name] = replay;
  replay_order_.push_back(name);
  if (replay_order_.size() > kReplaysKept) {
    replays_.erase(replay_order_.front());
    replay_order_.erase(replay_order_.begin());
  }
  return replay;
}

uint64_t RecordingServiceImpl::SeekLocked(Scene* scene, const std::string& name, const Replay& replay, size_t frame) {
  ReplayedScene& replayed = replayed_[scene->id()];
  const size_t needed = replay.edit_counts[frame];
  if (needed < replayed.edits) {
    throw Error(ErrorCode::kFailedPrecondition,
                "frame: " + std::to_string(frame) + " comes before edit " + std::to_string(replayed.edits) +
                    " (already applied to scene '" + scene->id() + "'); replay the recording again to go back past it");
  }
  for (; replayed.edits < needed; ++replayed.edits) {
    try {
      ReplayEdit(scene, replay.edits[replayed.edits], registry_->limits());
    } catch (const Error& error) {
      throw Error(ErrorCode::kFailedPrecondition, "recording '" + name + "', edit " +
                                                      std::to_string(replayed.edits + 1) + " (" +
                                                      replay.edits[replayed.edits].kind + "): " + error.what());
    }
  }
  const std::string what = "recording '" + name + "', frame " + std::to_string(frame);
  SceneState recorded = persistence::DecodeState(replay.states[frame], what);
  return scene->Update([&](const std::shared_ptr<const SceneModel>& model, SceneState* state) {
    if (recorded.body_poses.size() != model->bodies.size() || recorded.joint_positions.size() != model->joints.size()) {
      throw Error(ErrorCode::kFailedPrecondition, what + " does not fit scene '" + scene->id() + "'");
    }
    *state = std::move(recorded);
  });
}

grpc::ServerUnaryReactor* RecordingServiceImpl::ReplayRecording(Context* context,
                                                                const v1::ReplayRecordingRequest* request,
                                                                v1::ReplayRecordingResponse* response) {
  return RunUnary(context, "RecordingService/ReplayRecording", pool_, [=, this] {
    const auto replay = LoadReplay(request->name());
    auto scene = registry_->Create(request->scene_name().empty() ? "replay of " + request->name() : request->scene_name());
    try {
      std::lock_guard<std::mutex> lock(mutex_);
      replayed_[scene->id()] = {request->name(), 0};
      SeekLocked(scene.get(), request->name(), *replay, 0);
    } catch (...) {
      {
        std::lock_guard<std::mutex> lock(mutex_);
        replayed_.erase(scene->id());
      }
      registry_->Delete(scene->id());  // a replay that fails leaves no half-built scene behind
      throw;
    }
    response->set_scene_id(scene->id());
    response->set_frames(replay->states.size());
    for (double t : replay->times) response->add_frame_times(t);
  });
}

grpc::ServerUnaryReactor* RecordingServiceImpl::SeekReplay(Context* context, const v1::SeekReplayRequest* request,
                                                           v1::SeekReplayResponse* response) {
  return RunUnary(context, "RecordingService/SeekReplay", pool_, [=, this] {
    auto scene = registry_->Get(request->scene_id());
    const auto replay = LoadReplay(request->name());
    {
      // Only a replay's own scene: seeking must never overwrite a scene someone is working in.
      std::lock_guard<std::mutex> lock(mutex_);
      auto it = replayed_.find(scene->id());
      if (it == replayed_.end() || it->second.name != request->name()) {
        throw Error(ErrorCode::kFailedPrecondition, "scene_id: scene '" + scene->id() +
                                                        "' was not made by ReplayRecording of '" + request->name() + "'");
      }
    }
    if (request->frame() >= replay->states.size()) {
      ThrowInvalidArgument("frame: " + std::to_string(request->frame()) + " is past the last frame (" +
                           std::to_string(replay->states.size() - 1) + ")");
    }
    std::lock_guard<std::mutex> lock(mutex_);
    response->set_revision(SeekLocked(scene.get(), request->name(), *replay, request->frame()));
    response->set_time(replay->times[request->frame()]);
  });
}

}  // namespace graspsim::rpc
