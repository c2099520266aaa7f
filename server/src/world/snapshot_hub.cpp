#include "world/snapshot_hub.h"

#include <algorithm>

namespace graspsim {

void SnapshotHub::Publish(std::shared_ptr<const SceneSnapshot> snapshot) {
  std::vector<std::shared_ptr<SnapshotWatcher>> to_notify;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    latest_ = std::move(snapshot);
    for (const auto& weak : watchers_) {
      if (auto watcher = weak.lock()) to_notify.push_back(std::move(watcher));
    }
  }
  // Notified outside the lock: a watcher calls Latest() from its callback.
  for (const auto& watcher : to_notify) watcher->OnSnapshotAvailable();
}

void SnapshotHub::WantDetail(bool want, double interval) {
  std::lock_guard<std::mutex> lock(mutex_);
  if (want) {
    detail_intervals_.insert(interval);
  } else if (auto it = detail_intervals_.find(interval); it != detail_intervals_.end()) {
    detail_intervals_.erase(it);
  }
  detail_wanted_ = static_cast<int>(detail_intervals_.size());
}

double SnapshotHub::detail_interval() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return detail_intervals_.empty() ? 0 : *detail_intervals_.begin();
}

std::shared_ptr<const SceneSnapshot> SnapshotHub::Latest() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return latest_;
}

bool SnapshotHub::Subscribe(const std::shared_ptr<SnapshotWatcher>& watcher) {
  std::lock_guard<std::mutex> lock(mutex_);
  if (closed_) return false;
  std::erase_if(watchers_, [](const auto& weak) { return weak.expired(); });
  watchers_.push_back(watcher);
  return true;
}

void SnapshotHub::Unsubscribe(const SnapshotWatcher* watcher) {
  std::lock_guard<std::mutex> lock(mutex_);
  std::erase_if(watchers_, [watcher](const auto& weak) {
    auto locked = weak.lock();
    return !locked || locked.get() == watcher;
  });
}

void SnapshotHub::Close(const std::string& reason) {
  std::vector<std::shared_ptr<SnapshotWatcher>> to_close;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    closed_ = true;
    for (const auto& weak : watchers_) {
      if (auto watcher = weak.lock()) to_close.push_back(std::move(watcher));
    }
    watchers_.clear();
  }
  for (const auto& watcher : to_close) watcher->OnHubClosed(reason);
}

size_t SnapshotHub::WatcherCount() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return std::count_if(watchers_.begin(), watchers_.end(), [](const auto& weak) { return !weak.expired(); });
}

}  // namespace graspsim
