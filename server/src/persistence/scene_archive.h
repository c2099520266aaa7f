// A whole scene as one byte string (ExportScene/ImportScene): its name, the edits that built its model (the
// requests as received, uploaded files whole), its state and revision. Moving a scene to another server is
// replaying its edits there, as a restart does (edits/scene_restore.h), so the copy is built and validated
// exactly like the original. docs/scaling.md: scenes move by archive when a fleet grows.
#pragma once

#include <string>
#include <string_view>
#include <vector>

#include "world/scene_journal.h"
#include "world/state.h"

namespace graspsim::persistence {

struct SceneArchive {
  std::string id, name;
  uint64_t revision = 0;
  std::vector<SceneOp> ops;  // in order; UploadFile ops carry SceneOp::file
  SceneState state;
};

std::string EncodeSceneArchive(const SceneArchive& archive);
// Throws Error(kInvalidArgument) naming `field` when the bytes are not a whole archive this code wrote
// (wrong magic or version, truncated, trailing bytes, a file whose SHA-256 does not match).
SceneArchive DecodeSceneArchive(std::string_view bytes, const std::string& field);

}  // namespace graspsim::persistence
