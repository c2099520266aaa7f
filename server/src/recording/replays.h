// Recordings replayed into new scenes (RecordingService.ReplayRecording, SeekReplay; docs/recording.md): a
// recording read into memory (its edits and per frame its state), kept for the last few recordings and read again
// when its file changed; a new scene built from frame 0; seeks within it that apply the edits a frame's model
// needs and then its state. Only a replay's own scene can be sought: seeking never overwrites a scene someone
// works in. The recording's graspsim channels are the API's messages and the states the scene store's bytes, so
// reading and applying them is the caller's (ReplayCodec).
#pragma once

#include <cstdint>
#include <filesystem>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "recording/recorders.h"
#include "world/scene_journal.h"
#include "world/scene_registry.h"

namespace graspsim::recording {

// One frame of a recording's /graspsim/state channel.
struct RecordedFrame {
  double time = 0;     // s, simulated
  std::string state;   // the state as the caller's codec encodes it
  uint64_t edits = 0;  // how many of the recording's edits its model needs
};

// A recording read for replay.
struct Replay {
  std::vector<SceneOp> edits;
  std::vector<RecordedFrame> frames;
  std::pair<std::filesystem::file_time_type, uintmax_t> stamp;  // of the file read: a file replaced is read again
};

struct ReplayCodec {
  // A message of /graspsim/edit, /graspsim/state of recording `name`; throw Error(kFailedPrecondition) naming
  // the recording when it does not parse.
  std::function<SceneOp(const std::string& name, std::string_view message)> edit;
  std::function<RecordedFrame(const std::string& name, std::string_view message)> frame;
  // RecordedFrame::state back into a state; `what` names the frame for an error.
  std::function<SceneState(const std::string& state, const std::string& what)> decode_state;
  // Applies one recorded edit to a replayed scene.
  std::function<void(Scene* scene, const SceneOp& edit)> apply_edit;
};

class Replays {
 public:
  // `recorders`: where recordings live (names, paths, the ones still written); scenes are made in `registry`.
  // At most `kept` recordings stay in memory.
  Replays(Recorders* recorders, SceneRegistry* registry, ReplayCodec codec, size_t kept = 4);

  // Recording `name` read (or the copy in memory when its file is unchanged). Errors: PathOf's, kNotFound for
  // no such file, kFailedPrecondition while it is still being written, for a message the codec refuses, an
  // edit count past the edits recorded, or no state frames.
  std::shared_ptr<const Replay> Load(const std::string& name);

  // A new scene named `scene_name` ("" = "replay of <name>") at the recording's frame 0. All or nothing: a
  // replay that fails deletes its scene.
  struct Started {
    std::shared_ptr<Scene> scene;
    std::shared_ptr<const Replay> replay;
  };
  Started Start(const std::string& name, const std::string& scene_name);

  // The replayed scene `scene_id` moved to `frame` of recording `name`: kFailedPrecondition when the scene was
  // not made by Start of that recording or the frame comes before an edit already applied (replay again to go
  // back past it), or when an edit fails (naming the recording, the edit and its kind); kInvalidArgument for a
  // frame past the last.
  struct Sought {
    uint64_t revision = 0;
    double time = 0;  // s, the frame's
  };
  Sought Seek(const std::string& scene_id, const std::string& name, uint64_t frame);

 private:
  // Caller holds mutex_. Applies the edits the frame needs that the scene lacks, then its state.
  uint64_t SeekLocked(Scene* scene, const std::string& name, const Replay& replay, size_t frame);

  Recorders* const recorders_;
  SceneRegistry* const registry_;
  const ReplayCodec codec_;
  const size_t kept_;
  std::mutex mutex_;
  struct ReplayedScene {
    std::string name;  // the recording
    size_t edits = 0;  // of its edits applied
  };
  std::map<std::string, ReplayedScene> replayed_;                // by scene id: scenes made by Start
  std::map<std::string, std::shared_ptr<const Replay>> loaded_;  // by recording name, the last few loaded
  std::vector<std::string> order_;                               // of loaded_, oldest first
};

}  // namespace graspsim::recording
