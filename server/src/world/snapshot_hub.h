// Fan-out of scene snapshots to any number of watchers. The hub keeps only the newest snapshot; a watcher is
// told that a newer one exists and fetches it when it is ready to send, so a slow watcher skips snapshots
// instead of queueing them, and never slows the scene or the other watchers.
#pragma once

#include <atomic>
#include <cstdint>
#include <memory>
#include <mutex>
#include <set>
#include <string>
#include <vector>

namespace graspsim {

struct SceneOp;  // world/scene_journal.h
using SceneEdits = std::vector<std::shared_ptr<const SceneOp>>;

struct SceneSnapshot {
  uint64_t sequence = 0;  // per hub, +1 per publication
  uint64_t revision = 0;
  double time = 0;        // s
  std::shared_ptr<const std::vector<std::string>> body_ids;
  std::vector<double> body_poses;  // 7 per body: x y z qw qx qy qz
  std::shared_ptr<const std::vector<std::string>> joint_ids;
  std::vector<double> joint_positions;
  std::vector<double> contacts;         // 6 per contact: point x y z (m), force on body_a x y z (N), world
  std::vector<uint32_t> contact_bodies;  // 2 per contact: body_a, body_b (indices into body_ids)
  // The whole model and state, only while a watcher asked for them (SnapshotHub::WantDetail): a recording
  // encodes sensors, the exact state and the edits that built the model from them; other watchers need only
  // the flat arrays above.
  std::shared_ptr<const struct SceneModel> model;
  std::shared_ptr<const struct SceneState> state;
  std::shared_ptr<const SceneEdits> edits;  // every model edit so far, in order
};

class SnapshotWatcher {
 public:
  virtual ~SnapshotWatcher() = default;
  // A newer snapshot is available. Called from the publishing thread: must not block.
  virtual void OnSnapshotAvailable() = 0;
  // The hub is closing (scene deleted, server shutting down); the watcher should end its stream.
  virtual void OnHubClosed(const std::string& reason) = 0;
};

class SnapshotHub {
 public:
  void Publish(std::shared_ptr<const SceneSnapshot> snapshot);
  std::shared_ptr<const SceneSnapshot> Latest() const;
  // Returns false if the hub is already closed (the watcher is not added).
  bool Subscribe(const std::shared_ptr<SnapshotWatcher>& watcher);
  void Unsubscribe(const SnapshotWatcher* watcher);
  void Close(const std::string& reason);
  size_t WatcherCount() const;
  // Counted: snapshots carry the model and a copy of the state while at least one watcher wants them. `interval`
  // (simulated s) is the spacing of frames the watcher needs from a long update (Scene::PublishDuringUpdate);
  // withdraw with the same interval.
  void WantDetail(bool want, double interval = 0);
  bool detail_wanted() const { return detail_wanted_.load() > 0; }
  // The finest interval asked for (0 with no watcher wanting detail).
  double detail_interval() const;

 private:
  mutable std::mutex mutex_;
  std::shared_ptr<const SceneSnapshot> latest_;
  std::vector<std::weak_ptr<SnapshotWatcher>> watchers_;
  bool closed_ = false;
  std::atomic<int> detail_wanted_{0};
  std::multiset<double> detail_intervals_;
};

}  // namespace graspsim
