#include "world/scene_registry.h"

#include <algorithm>

#include "core/error.h"

namespace graspsim {

std::shared_ptr<Scene> SceneRegistry::Create(const std::string& name) {
  if (name.size() > 128) {
    ThrowInvalidArgument("name: " + std::to_string(name.size()) + " characters, at most 128 allowed");
  }
  std::shared_ptr<Scene> scene;
  std::function<void(const std::shared_ptr<Scene>&)> hook;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (scenes_.size() >= limits_.max_scenes) {
      ThrowResourceExhausted("the server already holds " + std::to_string(scenes_.size()) +
                             " scenes, the limit (--max-scenes) is " + std::to_string(limits_.max_scenes));
  }
    const std::string id = "scene-" + std::to_string(next_id_);
    scene = std::make_shared<Scene>(id, name, limits_);
    if (journal_) journal_->SceneCreated(id, name, next_id_ + 1);  // durable before anyone sees the id
    scene->AttachJournal(journal_);
    ++next_id_;
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
