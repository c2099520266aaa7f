#include "recording/replays.h"

#include <algorithm>

#include "core/error.h"
#include "recording/mcap_reader.h"

namespace graspsim::recording {

namespace fs = std::filesystem;

Replays::Replays(Recorders* recorders, SceneRegistry* registry, ReplayCodec codec, size_t kept)
    : recorders_(recorders), registry_(registry), codec_(std::move(codec)), kept_(kept) {}

std::shared_ptr<const Replay> Replays::Load(const std::string& name) {
  const std::string path = recorders_->PathOf("name", name);
  const std::string recording_scene = recorders_->ActiveSceneOf(name);
  if (!recording_scene.empty()) {
    throw Error(ErrorCode::kFailedPrecondition, "name: recording '" + name + "' of scene '" + recording_scene +
                                                    "' is still being written; stop it first");
  }
  std::error_code error;
  const auto stamp = std::make_pair(fs::last_write_time(path, error), fs::file_size(path, error));
  if (error) ThrowNotFound("name: no recording '" + name + "'");
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (auto it = loaded_.find(name); it != loaded_.end() && it->second->stamp == stamp) return it->second;
  }
  auto replay = std::make_shared<Replay>();
  replay->stamp = stamp;
  ReadMcap(path, name, [&](const McapMessage& message) {
    if (message.topic == "/graspsim/edit") {
      replay->edits.push_back(codec_.edit(name, message.data));
    } else if (message.topic == "/graspsim/state") {
      RecordedFrame frame = codec_.frame(name, message.data);
      if (frame.edits > replay->edits.size()) {
        throw Error(ErrorCode::kFailedPrecondition, "recording '" + name + "': a state needs edits not recorded");
      }
      replay->frames.push_back(std::move(frame));
    }
  });
  if (replay->frames.empty()) {
    throw Error(ErrorCode::kFailedPrecondition,
                "name: recording '" + name + "' has no /graspsim/state frames (recorded without the graspsim group?)");
  }
  std::lock_guard<std::mutex> lock(mutex_);
  if (loaded_.count(name)) order_.erase(std::find(order_.begin(), order_.end(), name));
  loaded_[name] = replay;
  order_.push_back(name);
  if (order_.size() > kept_) {
    loaded_.erase(order_.front());
    order_.erase(order_.begin());
  }
  return replay;
}

uint64_t Replays::SeekLocked(Scene* scene, const std::string& name, const Replay& replay, size_t frame) {
  ReplayedScene& replayed = replayed_[scene->id()];
  const size_t needed = replay.frames[frame].edits;
  if (needed < replayed.edits) {
    throw Error(ErrorCode::kFailedPrecondition,
                "frame: " + std::to_string(frame) + " comes before edit " + std::to_string(replayed.edits) +
                    " (already applied to scene '" + scene->id() + "'); replay the recording again to go back past it");
  }
  for (; replayed.edits < needed; ++replayed.edits) {
    try {
      codec_.apply_edit(scene, replay.edits[replayed.edits]);
    } catch (const Error& error) {
      throw Error(ErrorCode::kFailedPrecondition, "recording '" + name + "', edit " +
                                                      std::to_string(replayed.edits + 1) + " (" +
                                                      replay.edits[replayed.edits].kind + "): " + error.what());
    }
  }
  const std::string what = "recording '" + name + "', frame " + std::to_string(frame);
  SceneState recorded = codec_.decode_state(replay.frames[frame].state, what);
  return scene->Update([&](const std::shared_ptr<const SceneModel>& model, SceneState* state) {
    if (recorded.body_poses.size() != model->bodies.size() || recorded.joint_positions.size() != model->joints.size()) {
      throw Error(ErrorCode::kFailedPrecondition, what + " does not fit scene '" + scene->id() + "'");
    }
    *state = std::move(recorded);
  });
}

Replays::Started Replays::Start(const std::string& name, const std::string& scene_name) {
  const auto replay = Load(name);
  auto scene = registry_->Create(scene_name.empty() ? "replay of " + name : scene_name);
  try {
    std::lock_guard<std::mutex> lock(mutex_);
    replayed_[scene->id()] = {name, 0};
    SeekLocked(scene.get(), name, *replay, 0);
  } catch (...) {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      replayed_.erase(scene->id());
    }
    registry_->Delete(scene->id());  // a replay that fails leaves no half-built scene behind
    throw;
  }
  return {scene, replay};
}

Replays::Sought Replays::Seek(const std::string& scene_id, const std::string& name, uint64_t frame) {
  auto scene = registry_->Get(scene_id);
  const auto replay = Load(name);
  std::lock_guard<std::mutex> lock(mutex_);
  // Only a replay's own scene: seeking must never overwrite a scene someone is working in.
  auto it = replayed_.find(scene->id());
  if (it == replayed_.end() || it->second.name != name) {
    throw Error(ErrorCode::kFailedPrecondition,
                "scene_id: scene '" + scene->id() + "' was not made by ReplayRecording of '" + name + "'");
  }
  if (frame >= replay->frames.size()) {
    ThrowInvalidArgument("frame: " + std::to_string(frame) + " is past the last frame (" +
                         std::to_string(replay->frames.size() - 1) + ")");
  }
  return {SeekLocked(scene.get(), name, *replay, frame), replay->frames[frame].time};
}

}  // namespace graspsim::recording
