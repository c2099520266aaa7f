// Start-up: the scenes of the scene store (persistence/scene_store.h) rebuilt in the registry. Each scene's
// stored requests run through the RPCs' own code (scene_edits.h) in the order they were accepted, then its
// stored state and revision are put back; after that the registry journals every edit to the store.
#pragma once

#include "persistence/scene_archive.h"
#include "persistence/scene_store.h"
#include "world/scene_registry.h"

namespace graspsim::rpc {

// One stored edit run through the RPC's code (a restart, a recording's replay). Throws what that code throws;
// Error(kInternal) for a request that does not parse or an unknown kind.
void ReplayEdit(Scene* scene, const SceneOp& op, const Limits& limits);

// Throws Error(kFailedPrecondition) naming the database, the scene and the stored edit that cannot be replayed.
// Returns the number of scenes restored.
size_t RestoreScenes(persistence::SceneStore* store, SceneRegistry* registry);

// A scene as it is now, to move it (ExportScene): its edits, files, state and revision, taken at one instant.
persistence::SceneArchive ArchiveOf(const Scene& scene);
// A new scene rebuilt from an archive under `id` (empty = the archive's), journaled like any edit. All or
// nothing: an edit that fails deletes the new scene again and throws Error(kInvalidArgument) naming the edit.
std::shared_ptr<Scene> ImportArchive(const persistence::SceneArchive& archive, const std::string& id,
                                     SceneRegistry* registry);

}  // namespace graspsim::rpc
