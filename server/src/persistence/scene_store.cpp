#include "persistence/scene_store.h"

#include <sqlite3.h>


#include "core/error.h"
#include "core/sha256.h"
#include "core/sqlite_file.h"
#include "persistence/state_codec.h"

namespace graspsim::persistence {
namespace {

constexpr int kSchemaVersion = 1;

constexpr char kLabel[] = "scene store ";

[[noreturn]] void ThrowStore(const std::string& path, const std::string& what) { ThrowStoreError(kLabel, path, what); }

// A failed write during a request: the request fails and nothing of it is stored.
[[noreturn]] void ThrowWrite(const std::string& path, sqlite3* db) {
  throw Error(ErrorCode::kInternal, "scene store " + path + ": cannot write: " + sqlite3_errmsg(db));
}

void Exec(sqlite3* db, const std::string& path, const char* sql) { ExecSql(db, kLabel, path, sql); }

class Statement {
 public:
  Statement(sqlite3* db, const std::string& path, const char* sql) : db_(db), path_(path) {
    if (sqlite3_prepare_v2(db, sql, -1, &stmt_, nullptr) != SQLITE_OK) ThrowWrite(path, db);
  }
  ~Statement() { sqlite3_finalize(stmt_); }
  Statement& Text(int i, const std::string& v) {
    sqlite3_bind_text(stmt_, i, v.data(), static_cast<int>(v.size()), SQLITE_STATIC);
    return *this;
  }
  Statement& Blob(int i, const std::string& v) {
    sqlite3_bind_blob64(stmt_, i, v.data(), v.size(), SQLITE_STATIC);
    return *this;
  }
  Statement& Int(int i, int64_t v) {
    sqlite3_bind_int64(stmt_, i, v);
    return *this;
  }
  void Run() {
    if (sqlite3_step(stmt_) != SQLITE_DONE) ThrowWrite(path_, db_);
  }
  // For queries: true while there is a row.
  bool Next() {
    const int rc = sqlite3_step(stmt_);
    if (rc == SQLITE_ROW) return true;
    if (rc != SQLITE_DONE) ThrowStore(path_, std::string("cannot read: ") + sqlite3_errmsg(db_));
    return false;
  }
  std::string ColumnText(int i) const {
    const auto* p = reinterpret_cast<const char*>(sqlite3_column_blob(stmt_, i));
    return p ? std::string(p, sqlite3_column_bytes(stmt_, i)) : std::string();
  }
  int64_t ColumnInt(int i) const { return sqlite3_column_int64(stmt_, i); }

 private:
  sqlite3* db_;
  const std::string& path_;  // the store's, which outlives every statement
  sqlite3_stmt* stmt_ = nullptr;
};

}  // namespace

SceneStore::SceneStore(const std::string& directory) {
  // FULL: the WAL is fsync'ed at every commit, so an acknowledged write survives a power cut too, not only a
  // crash of the process (NORMAL would fsync only at checkpoints). docs/durability.md has its cost.
  db_ = OpenStoreFile(kLabel, directory, "scenes.sqlite", "FULL", &path_);
  try {
    // A large upload grows the WAL; give the space back after the checkpoint that follows it.
    Exec(db_, path_, "PRAGMA journal_size_limit=67108864");
    Exec(db_, path_,
         "CREATE TABLE IF NOT EXISTS meta (key TEXT PRIMARY KEY, value INTEGER NOT NULL);"
         "CREATE TABLE IF NOT EXISTS scenes (seq INTEGER PRIMARY KEY AUTOINCREMENT, id TEXT NOT NULL UNIQUE,"
         " name TEXT NOT NULL, revision INTEGER NOT NULL, state BLOB NOT NULL);"
         "CREATE TABLE IF NOT EXISTS scene_ops (scene_id TEXT NOT NULL, seq INTEGER NOT NULL, kind TEXT NOT NULL,"
         " path TEXT NOT NULL, sha256 TEXT NOT NULL, payload BLOB NOT NULL, PRIMARY KEY (scene_id, seq));"
         "INSERT OR IGNORE INTO meta (key, value) VALUES ('schema_version', 1), ('next_id', 1);");
    Statement version(db_, path_, "SELECT value FROM meta WHERE key = 'schema_version'");
    if (!version.Next() || version.ColumnInt(0) != kSchemaVersion) {
      ThrowStore(path_, "schema version " + version.ColumnText(0) + ", this server reads version " +
                            std::to_string(kSchemaVersion));
    }
  } catch (...) {
    sqlite3_close(db_);
    throw;
  }
  writer_ = std::thread([this] { WriterLoop(); });
}

SceneStore::~SceneStore() {
  {
    std::lock_guard<std::mutex> lock(queue_mutex_);
    stopping_ = true;
  }
  queue_cv_.notify_all();
  writer_.join();
  sqlite3_close(db_);
}

void SceneStore::Write(std::function<void()> statements) {
  Job job{std::move(statements), nullptr, false};
  std::unique_lock<std::mutex> lock(queue_mutex_);
  queue_.push_back(&job);
  queue_cv_.notify_one();
  done_cv_.wait(lock, [&] { return job.done; });
  if (job.error) std::rethrow_exception(job.error);
}

void SceneStore::WriterLoop() {
  std::unique_lock<std::mutex> lock(queue_mutex_);
  for (;;) {
    queue_cv_.wait(lock, [&] { return stopping_ || !queue_.empty(); });
    if (queue_.empty()) return;  // stopping, nothing left to write
    // Everything that queued while the last commit was being synced goes into this one.
    const std::vector<Job*> batch(queue_.begin(), queue_.end());
    queue_.clear();
    lock.unlock();
    RunBatch(batch);
    lock.lock();
    for (Job* job : batch) job->done = true;
    done_cv_.notify_all();
  }
}

void SceneStore::RunBatch(const std::vector<Job*>& batch) {
  std::lock_guard<std::mutex> lock(mutex_);
  auto fail_all = [&](std::exception_ptr error) {
    for (Job* job : batch) {
      if (!job->error) job->error = error;
    }
  };
  if (sqlite3_exec(db_, "BEGIN IMMEDIATE", nullptr, nullptr, nullptr) != SQLITE_OK) {
    try {
      ThrowWrite(path_, db_);
    } catch (...) {
      fail_all(std::current_exception());
    }
    return;
  }
  for (Job* job : batch) {
    sqlite3_exec(db_, "SAVEPOINT write", nullptr, nullptr, nullptr);
    try {
      job->statements();
      sqlite3_exec(db_, "RELEASE write", nullptr, nullptr, nullptr);
    } catch (...) {
      job->error = std::current_exception();
      sqlite3_exec(db_, "ROLLBACK TO write", nullptr, nullptr, nullptr);
      sqlite3_exec(db_, "RELEASE write", nullptr, nullptr, nullptr);
    }
  }
  try {
    BeforeCommit();
    if (sqlite3_exec(db_, "COMMIT", nullptr, nullptr, nullptr) != SQLITE_OK) ThrowWrite(path_, db_);
  } catch (...) {
    fail_all(std::current_exception());
    sqlite3_exec(db_, "ROLLBACK", nullptr, nullptr, nullptr);
  }
}

StoredScenes SceneStore::Load() const {
  std::lock_guard<std::mutex> lock(mutex_);
  StoredScenes out;
  Statement next(db_, path_, "SELECT value FROM meta WHERE key = 'next_id'");
  if (next.Next()) out.next_id = static_cast<uint64_t>(next.ColumnInt(0));
  Statement scenes(db_, path_, "SELECT id, name, revision, state FROM scenes ORDER BY seq");
  while (scenes.Next()) {
    StoredScene scene;
    scene.id = scenes.ColumnText(0);
    scene.name = scenes.ColumnText(1);
    scene.revision = static_cast<uint64_t>(scenes.ColumnInt(2));
    try {
      scene.state = DecodeState(scenes.ColumnText(3), "scene store " + path_ + ": the state of " + scene.id);
    } catch (const Error& error) {
      ThrowStore(path_, error.what());
    }
    out.scenes.push_back(std::move(scene));
  }
  for (StoredScene& scene : out.scenes) {
    Statement ops(db_, path_, "SELECT kind, path, sha256, payload FROM scene_ops WHERE scene_id = ?1 ORDER BY seq");
    ops.Text(1, scene.id);
    while (ops.Next()) {
      SceneOp op;
      op.kind = ops.ColumnText(0);
      op.path = ops.ColumnText(1);
      op.sha256 = ops.ColumnText(2);
      if (op.kind == "UploadFile") {
        auto bytes = std::make_shared<const std::string>(ops.ColumnText(3));
        // The file was checked against its SHA-256 before it was stored; a mismatch now is a damaged database.
        if (Sha256Hex(*bytes) != op.sha256) {
          ThrowStore(path_, "file '" + op.path + "' of " + scene.id + " no longer matches its SHA-256");
        }
        op.file = std::move(bytes);
      } else {
        op.payload = ops.ColumnText(3);
      }
      scene.ops.push_back(std::move(op));
    }
  }
  return out;
}

void SceneStore::SceneCreated(const std::string& id, const std::string& name, uint64_t next_id) {
  const std::string state = EncodeState(SceneState());
  Write([&] {
    Statement(db_, path_, "INSERT INTO scenes (id, name, revision, state) VALUES (?1, ?2, 0, ?3)")
        .Text(1, id).Text(2, name).Blob(3, state).Run();
    Statement(db_, path_, "UPDATE meta SET value = ?1 WHERE key = 'next_id'")
        .Int(1, static_cast<int64_t>(next_id)).Run();
  });
}

void SceneStore::SceneDeleted(const std::string& id) {
  Write([&] {
    Statement(db_, path_, "DELETE FROM scene_ops WHERE scene_id = ?1").Text(1, id).Run();
    Statement(db_, path_, "DELETE FROM scenes WHERE id = ?1").Text(1, id).Run();
  });
}

void SceneStore::SceneChanged(const std::string& id, const SceneOp* op, const SceneState& state, uint64_t revision) {
  const std::string encoded = EncodeState(state);  // on the caller's thread, not the writer's
  Write([&] {
    if (op) {
      Statement(db_, path_,
                "INSERT INTO scene_ops (scene_id, seq, kind, path, sha256, payload) VALUES (?1,"
                " (SELECT COALESCE(MAX(seq), 0) + 1 FROM scene_ops WHERE scene_id = ?1), ?2, ?3, ?4, ?5)")
          .Text(1, id).Text(2, op->kind).Text(3, op->path).Text(4, op->sha256)
          .Blob(5, op->file ? *op->file : op->payload).Run();
    }
    Statement(db_, path_, "UPDATE scenes SET state = ?2, revision = ?3 WHERE id = ?1")
        .Text(1, id).Blob(2, encoded).Int(3, static_cast<int64_t>(revision)).Run();
    if (sqlite3_changes(db_) != 1) {
      throw Error(ErrorCode::kInternal, "scene store " + path_ + ": scene '" + id + "' is not stored");
    }
  });
}

}  // namespace graspsim::persistence
