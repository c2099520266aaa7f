// Scenes that survive restarts and crashes: an embedded SQLite database (<directory>/scenes.sqlite) that is
// the SceneRegistry's journal (world/scene_journal.h). Per scene it keeps its id and name, the log of the edits
// that built its model (the requests as received, uploaded files whole) and its newest state; every write is
// one transaction, committed (WAL, synchronous=FULL: on disk, not only in the OS cache) before the request
// that made it is answered. docs/durability.md states what is stored when.
//
// Group commit: one writer thread commits whatever writes are waiting together, each in its own savepoint, so
// concurrent requests (other scenes, other clients) share one fsync instead of queueing for one each; every
// caller still returns only after the commit that holds its write. A write that fails alone (its statements)
// is rolled back alone; a failed COMMIT fails every write of that batch.
#pragma once

#include <condition_variable>
#include <cstdint>
#include <deque>
#include <exception>
#include <functional>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "world/scene_journal.h"

struct sqlite3;

namespace graspsim::persistence {

struct StoredScene {
  std::string id, name;
  uint64_t revision = 0;
  SceneState state;
  std::vector<SceneOp> ops;  // in the order they were accepted; UploadFile ops carry SceneOp::file
};

struct StoredScenes {
  std::vector<StoredScene> scenes;  // in creation order
  uint64_t next_id = 1;             // the number of the next scene id ("scene-<n>")
};

class SceneStore : public SceneJournal {
 public:
  // Opens (creating the directory and the database when missing). Throws Error(kFailedPrecondition) naming the
  // database's path when it cannot, or when the file is not a database of ours; it never deletes or rewrites
  // such a file.
  explicit SceneStore(const std::string& directory);
  ~SceneStore() override;
  SceneStore(const SceneStore&) = delete;
  SceneStore& operator=(const SceneStore&) = delete;

  // Everything committed. Throws Error(kFailedPrecondition) naming the path when a row cannot be read.
  StoredScenes Load() const;
  const std::string& path() const { return path_; }

  void SceneCreated(const std::string& id, const std::string& name, uint64_t next_id) override;
  void SceneDeleted(const std::string& id) override;
  void SceneChanged(const std::string& id, const SceneOp* op, const SceneState& state, uint64_t revision) override;

 protected:
  // Called inside every write transaction just before COMMIT (on the writer thread); a test overrides it to
  // throw and checks that the transaction left nothing behind.
  virtual void BeforeCommit() {}

 private:
  struct Job {
    std::function<void()> statements;
    std::exception_ptr error;
    bool done = false;
  };
  // Queues `statements` for the next batch and waits until the batch is committed (or failed: then throws).
  void Write(std::function<void()> statements);
  void WriterLoop();
  void RunBatch(const std::vector<Job*>& batch);

  std::string path_;
  sqlite3* db_ = nullptr;
  mutable std::mutex mutex_;  // one connection: the writer thread, or Load
  std::mutex queue_mutex_;
  std::condition_variable queue_cv_, done_cv_;
  std::deque<Job*> queue_;
  bool stopping_ = false;
  std::thread writer_;
};

}  // namespace graspsim::persistence
