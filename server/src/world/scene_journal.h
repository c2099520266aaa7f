// Where a scene's accepted edits go to survive a restart (implemented by server/src/persistence). A scene calls
// its journal under its own lock, after the edit was validated and before it becomes visible: when the call
// throws, the edit is dropped and the request fails; when it returns, the edit is durable, so the reply that
// follows acknowledges a stored write.
#pragma once

#include <cstdint>
#include <memory>
#include <string>

#include "world/state.h"

namespace graspsim {

// An edit of the model, as the layer that accepted it describes it. `payload` is opaque to the world library:
// the typed edit API stores its edit record (edits/edit_codec.h) and replays it through the same code on start
// (edits/scene_restore.h), so a restored scene is built exactly like the original.
struct SceneOp {
  std::string kind;     // "AddObject", "AddRobot", "RemoveBody", "SetSimulationParams", "UploadFile"
  std::string payload;  // the edit record (empty for UploadFile)
  // UploadFile only: the file's path, SHA-256 (hex) and bytes (shared with the scene, not copied).
  std::string path, sha256;
  std::shared_ptr<const std::string> file;
};

class SceneJournal {
 public:
  virtual ~SceneJournal() = default;
  // Each call is one transaction, durable when it returns; it throws graspsim::Error and stores nothing when it
  // cannot write.
  virtual void SceneCreated(const std::string& id, const std::string& name, uint64_t next_id) = 0;
  virtual void SceneDeleted(const std::string& id) = 0;
  // The scene after an edit: `op` (null for a change of state only: poses, joints, actuators, simulation steps)
  // is appended to the scene's log and `state` with `revision` replaces the stored state.
  virtual void SceneChanged(const std::string& id, const SceneOp* op, const SceneState& state,
                            uint64_t revision) = 0;
};

}  // namespace graspsim
