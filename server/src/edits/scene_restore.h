// Scenes rebuilt from stored edits: at start from the scene store, from an archive (ImportScene), and one edit at
// a time by a recording's replay. Each stored op runs through the typed edit API (scene_edits.h) in the order it
// was accepted, so a restored scene is built, and checked, exactly like the original; then its stored state and
// revision are put back. Ops journaled before edit records (version 1) are read by the caller's LegacyEditReader.
#pragma once

#include <memory>
#include <string>

#include "edits/edit_codec.h"
#include "persistence/scene_archive.h"
#include "persistence/scene_store.h"
#include "world/scene_registry.h"

namespace graspsim::edits {

// One stored op applied. Throws what the edit throws; Error(kInternal) for a record that does not parse.
void ReplayEdit(Scene* scene, const SceneOp& op, const Limits& limits, const LegacyEditReader& legacy);

// Throws Error(kFailedPrecondition) naming the database, the scene and the stored edit that cannot be replayed.
// Returns the number of scenes restored; after that the registry journals every edit to the store.
size_t RestoreScenes(persistence::SceneStore* store, SceneRegistry* registry, const LegacyEditReader& legacy);

// A scene as it is now, to move it (ExportScene): its edits, files, state and revision, taken at one instant.
persistence::SceneArchive ArchiveOf(const Scene& scene);

// A new scene rebuilt from an archive under `id` (empty = the archive's), journaled like any edit. All or
// nothing: an edit that fails deletes the new scene again and throws Error(kInvalidArgument) naming the edit.
std::shared_ptr<Scene> ImportArchive(const persistence::SceneArchive& archive, const std::string& id,
                                     SceneRegistry* registry, const LegacyEditReader& legacy);

}  // namespace graspsim::edits
