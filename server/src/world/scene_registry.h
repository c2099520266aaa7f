// All scenes of a server. The registry lock guards only the id → scene map; each scene has its own lock, so a
// slow request on one scene never blocks another.
#pragma once

#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "core/limits.h"
#include "world/scene.h"

namespace graspsim {

class SceneRegistry {
 public:
  explicit SceneRegistry(const Limits& limits) : limits_(limits) {}

  const Limits& limits() const { return limits_; }
  // `requested_id` empty: the server's next id "scene-<n>"; else that id (1-64 of [A-Za-z0-9._-], not of the form
  // scene-<n>). Errors: kInvalidArgument (name longer than 128 characters, a bad id), kAlreadyExists (the id is
  // taken), kResourceExhausted (too many scenes).
  std::shared_ptr<Scene> Create(const std::string& name, const std::string& requested_id = "");
  // A scene moved here from another server (ImportScene) under its id there, of the form scene-<n> too; the
  // ids this server makes then continue past n. Errors as Create.
  std::shared_ptr<Scene> CreateMoved(const std::string& name, const std::string& id);
  // Error: kNotFound naming the id.
  std::shared_ptr<Scene> Get(const std::string& id) const;
  // The same without waiting: null while the registry is busy (a scene being created or deleted commits its
  // journal entry under the lock); Error(kNotFound) as Get.
  std::shared_ptr<Scene> TryGet(const std::string& id) const;
  std::vector<std::shared_ptr<Scene>> List() const;
  void Delete(const std::string& id);

  // Start-up replay (edits/scene_restore.h): a scene under its stored id and name, not journaled; later ids
  // start at `next_id` (ids are never reused, even of deleted scenes).
  std::shared_ptr<Scene> Restore(const std::string& id, const std::string& name);
  void SetNextId(uint64_t next_id);
  // From now on every scene's edits, creations and deletions go to `journal` (it outlives the registry).
  void AttachJournal(SceneJournal* journal);
  // Called with every scene Create makes, after it is registered, outside the registry lock (--record).
  void SetCreatedHook(std::function<void(const std::shared_ptr<Scene>&)> hook);
  // Ends every watcher stream of every scene (server shutdown).
  void CloseAllWatchers(const std::string& reason);

 private:
  std::shared_ptr<Scene> CreateWith(const std::string& name, const std::string& requested_id, bool server_form_allowed);

  const Limits limits_;
  mutable std::mutex mutex_;
  std::map<std::string, std::shared_ptr<Scene>> scenes_;
  uint64_t next_id_ = 1;
  SceneJournal* journal_ = nullptr;
  std::function<void(const std::shared_ptr<Scene>&)> created_hook_;
};

}  // namespace graspsim
