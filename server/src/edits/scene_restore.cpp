#include "edits/scene_restore.h"

#include <algorithm>

#include "core/error.h"
#include "edits/scene_edits.h"

namespace graspsim::edits {

void ReplayEdit(Scene* scene, const SceneOp& op, const Limits& limits, const LegacyEditReader& legacy) {
  if (op.kind == "UploadFile") {
    scene->PutFile(op.path, op.file, op.sha256, &op);
    return;
  }
  // A version-1 op is applied as its record, and journaled as one from then on.
  Apply(scene, IsEditRecord(op) ? DecodeEdit(op) : legacy(op), limits);
}

size_t RestoreScenes(persistence::SceneStore* store, SceneRegistry* registry, const LegacyEditReader& legacy) {
  persistence::StoredScenes stored = store->Load();
  for (persistence::StoredScene& saved : stored.scenes) {
    auto scene = registry->Restore(saved.id, saved.name);
    for (size_t i = 0; i < saved.ops.size(); ++i) {
      try {
        ReplayEdit(scene.get(), saved.ops[i], registry->limits(), legacy);
      } catch (const Error& error) {
        // A limit lowered since (--max-bodies-per-scene, --max-upload-bytes …) lands here too: the message says so.
        throw Error(ErrorCode::kFailedPrecondition, "scene store " + store->path() + ": scene '" + saved.id +
                                                        "', stored edit " + std::to_string(i + 1) + " (" +
                                                        saved.ops[i].kind + "): " + error.what());
      }
    }
    try {
      scene->RestoreState(std::move(saved.state), saved.revision);
    } catch (const Error& error) {
      throw Error(ErrorCode::kFailedPrecondition, "scene store " + store->path() + ": " + error.what());
    }
  }
  registry->SetNextId(stored.next_id);
  registry->AttachJournal(store);
  return stored.scenes.size();
}

persistence::SceneArchive ArchiveOf(const Scene& scene) {
  const std::shared_ptr<const SceneSnapshot> snapshot = scene.DetailedSnapshot();
  persistence::SceneArchive archive;
  archive.id = scene.id();
  archive.name = scene.View().name;
  archive.revision = snapshot->revision;
  for (const auto& op : *snapshot->edits) archive.ops.push_back(*op);
  archive.state = *snapshot->state;
  return archive;
}

std::shared_ptr<Scene> ImportArchive(const persistence::SceneArchive& archive, const std::string& id,
                                     SceneRegistry* registry, const LegacyEditReader& legacy) {
  auto scene = registry->CreateMoved(archive.name, id.empty() ? archive.id : id);
  try {
    for (size_t i = 0; i < archive.ops.size(); ++i) {
      try {
        ReplayEdit(scene.get(), archive.ops[i], registry->limits(), legacy);
      } catch (const Error& error) {
        ThrowInvalidArgument("data: the archive's edit " + std::to_string(i + 1) + " (" + archive.ops[i].kind +
                             ") does not apply here: " + error.what());
      }
    }
    // A revision above every one the new scene had, so that its watchers see the restored state as news and the
    // journal stores it.
    try {
      scene->RestoreState(archive.state, std::max(archive.revision, scene->revision() + 1));
    } catch (const Error& error) {
      ThrowInvalidArgument(std::string("data: the archive's state does not fit its model: ") + error.what());
    }
    scene->Checkpoint();
  } catch (...) {
    registry->Delete(scene->id());
    throw;
  }
  return scene;
}

}  // namespace graspsim::edits
