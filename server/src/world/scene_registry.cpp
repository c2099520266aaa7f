#include "world/scene_registry.h"

#include <algorithm>
#include <cctype>

#include "core/error.h"

namespace graspsim {

namespace {

std::string Quoted(const std::string& s) { return "'" + s + "'"; }

// A client-chosen id (a fleet routes a scene's calls by it before the scene exists, docs/scaling.md): 1-64
// characters a URL and a metadata header carry as they are; never of the server's own form scene-<n>, so the
// ids the server makes stay unique.
// The n of a server-made id "scene-<n>", else 0.
uint64_t ServerIdNumber(const std::string& id) {
  if (!id.starts_with("scene-") || id.size() == 6 || id.size() > 26 ||
      !std::all_of(id.begin() + 6, id.end(), [](char c) { return std::isdigit(static_cast<unsigned char>(c)); })) {
    return 0;
  }
  return std::stoull(id.substr(6));
}

void CheckClientId(const std::string& id, bool server_form_allowed) {
  const bool allowed = !id.empty() && id.size() <= 64 && std::all_of(id.begin(), id.end(), [](char c) {
    return std::isalnum(static_cast<unsigned char>(c)) || c == '-' || c == '_' || c == '.';
  });
  if (!allowed) {
    ThrowInvalidArgument("scene_id: " + Quoted(id.substr(0, 80)) +
                         " is not 1-64 characters of letters, digits, '-', '_' and '.'");
  }
  if (!server_form_allowed && ServerIdNumber(id) > 0) {
    ThrowInvalidArgument("scene_id: " + Quoted(id) + " has the form scene-<n> of the ids the server makes; choose another");
  }
}

}  // namespace

std::shared_ptr<Scene> SceneRegistry::Create(const std::string& name, const std::string& requested_id) {
  return CreateWith(name, requested_id, false);
}

std::shared_ptr<Scene> SceneRegistry::CreateMoved(const std::string& name, const std::string& id) {
  return CreateWith(name, id, true);
}

std::shared_ptr<Scene> SceneRegistry::CreateWith(const std::string& name, const std::string& requested_id,
                                                 bool server_form_allowed) {
  if (name.size() > 128) {
    ThrowInvalidArgument("name: " + std::to_string(name.size()) + " characters, at most 128 allowed");
  }
  if (!requested_id.empty() || server_form_allowed) CheckClientId(requested_id, server_form_allowed);
  std::shared_ptr<Scene> scene;
  std::function<void(const std::shared_ptr<Scene>&)> hook;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (!requested_id.empty() && scenes_.count(requested_id)) {
      throw Error(ErrorCode::kAlreadyExists, "scene_id: " + Quoted(requested_id) + " already exists");
    }
    if (scenes_.size() >= limits_.max_scenes) {
      ThrowResourceExhausted("the server already holds " + std::to_string(scenes_.size()) +
                             " scenes, the limit (--max-scenes) is " + std::to_string(limits_.max_scenes));
    }
    const bool generated = requested_id.empty();
    const std::string id = generated ? "scene-" + std::to_string(next_id_) : requested_id;
    // A moved scene of the form scene-<n> keeps the ids this server makes past its own.
    const uint64_t next_id = generated ? next_id_ + 1 : std::max(next_id_, ServerIdNumber(id) + 1);
    scene = std::make_shared<Scene>(id, name, limits_);
    if (journal_) journal_->SceneCreated(id, name, next_id);  // durable before anyone sees the id
    scene->AttachJournal(journal_);
    next_id_ = next_id;
    scenes_[id] = scene;
    hook = created_hook_;
  }
  if (hook) hook(scene);
  return scene;
}

void SceneRegistry::SetCreatedHook(std::function<void(const std::shared_ptr<Scene>&)> hook) {
  std::lock_guard<std::mutex> lock(mutex_);
  created_hook_ = std::move(hook);
}

std::shared_ptr<Scene> SceneRegistry::Get(const std::string& id) const {
  std::lock_guard<std::mutex> lock(mutex_);
  auto it = scenes_.find(id);
  if (it == scenes_.end()) ThrowNotFound("scene_id: no scene '" + id.substr(0, 80) + "'");
  return it->second;
}

std::shared_ptr<Scene> SceneRegistry::TryGet(const std::string& id) const {
  std::unique_lock<std::mutex> lock(mutex_, std::try_to_lock);
  if (!lock.owns_lock()) return nullptr;
  auto it = scenes_.find(id);
  if (it == scenes_.end()) ThrowNotFound("scene_id: no scene '" + id.substr(0, 80) + "'");
  return it->second;
}

std::vector<std::shared_ptr<Scene>> SceneRegistry::List() const {
  std::lock_guard<std::mutex> lock(mutex_);
  std::vector<std::shared_ptr<Scene>> scenes;
  for (const auto& [id, scene] : scenes_) scenes.push_back(scene);
  return scenes;
}

void SceneRegistry::Delete(const std::string& id) {
  std::shared_ptr<Scene> scene;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    auto it = scenes_.find(id);
    if (it == scenes_.end()) ThrowNotFound("scene_id: no scene '" + id.substr(0, 80) + "'");
    if (journal_) journal_->SceneDeleted(id);
    scene = std::move(it->second);
    scenes_.erase(it);
  }
  scene->CloseWatchers("scene '" + id + "' was deleted");
}

std::shared_ptr<Scene> SceneRegistry::Restore(const std::string& id, const std::string& name) {
  std::lock_guard<std::mutex> lock(mutex_);
  auto scene = std::make_shared<Scene>(id, name, limits_);
  scenes_[id] = scene;
  return scene;
}

void SceneRegistry::SetNextId(uint64_t next_id) {
  std::lock_guard<std::mutex> lock(mutex_);
  next_id_ = std::max(next_id_, next_id);
}

void SceneRegistry::AttachJournal(SceneJournal* journal) {
  std::lock_guard<std::mutex> lock(mutex_);
  journal_ = journal;
  for (const auto& [id, scene] : scenes_) scene->AttachJournal(journal);
}

void SceneRegistry::CloseAllWatchers(const std::string& reason) {
  for (const auto& scene : List()) scene->CloseWatchers(reason);
}

}  // namespace graspsim
