#include "rpc/scene_replay.h"

#include "core/error.h"
#include "rpc/scene_edits.h"

namespace graspsim::rpc {
namespace {

template <typename Request>
Request Parse(const SceneOp& op) {
  Request request;
  if (!request.ParseFromString(op.payload)) throw Error(ErrorCode::kInternal, "the stored request does not parse");
  return request;
}

}  // namespace

void ReplayEdit(Scene* scene, const SceneOp& op, const Limits& limits) {
  if (op.kind == "UploadFile") {
    scene->PutFile(op.path, op.file, op.sha256, &op);
  } else if (op.kind == "AddObject") {
    AddObjectFromRequest(scene, Parse<v1::AddObjectRequest>(op), limits, nullptr);
  } else if (op.kind == "AddRobot") {
    AddRobotFromRequest(scene, Parse<v1::AddRobotRequest>(op), limits, nullptr);
  } else if (op.kind == "RemoveBody") {
    RemoveBodyFromRequest(scene, Parse<v1::RemoveBodyRequest>(op));
  } else if (op.kind == "SetSimulationParams") {
    SetSimulationParamsFromRequest(scene, Parse<v1::SetSimulationParamsRequest>(op), nullptr);
  } else {
    throw Error(ErrorCode::kInternal, "unknown edit kind '" + op.kind + "'");
  }
}

size_t RestoreScenes(persistence::SceneStore* store, SceneRegistry* registry) {
  persistence::StoredScenes stored = store->Load();
  for (persistence::StoredScene& saved : stored.scenes) {
    auto scene = registry->Restore(saved.id, saved.name);
    for (size_t i = 0; i < saved.ops.size(); ++i) {
      try {
        ReplayEdit(scene.get(), saved.ops[i], registry->limits());
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

}  // namespace graspsim::rpc
