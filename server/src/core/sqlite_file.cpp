#include "core/sqlite_file.h"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <vector>

#include <sqlite3.h>

#include "core/error.h"

namespace graspsim {

void ThrowStoreError(const std::string& label, const std::string& path, const std::string& what) {
  throw Error(ErrorCode::kFailedPrecondition, label + path + ": " + what);
}

void ExecSql(sqlite3* db, const std::string& label, const std::string& path, const char* sql) {
  char* message = nullptr;
  if (sqlite3_exec(db, sql, nullptr, nullptr, &message) != SQLITE_OK) {
    const std::string text = message ? message : sqlite3_errmsg(db);
    sqlite3_free(message);
    ThrowStoreError(label, path, text);
  }
}

namespace {

// fsync of a directory: the names in it (a new file's, a new directory's) survive a power cut only after it.
bool SyncDirectory(const std::filesystem::path& directory) {
  const int fd = ::open(directory.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (fd < 0) return false;
  const bool ok = ::fsync(fd) == 0;
  ::close(fd);
  return ok;
}

}  // namespace

sqlite3* OpenStoreFile(const std::string& label, const std::string& directory, const std::string& file_name,
                       const char* synchronous, std::string* path) {
  std::error_code error;
  // The directories created here (the data directory on a first start) must outlive a power cut with the database
  // in them: SQLite syncs its files' own directory, never the ones above it (tests/bench/power_cut.py found this).
  std::vector<std::filesystem::path> created;
  for (auto p = std::filesystem::absolute(directory, error).lexically_normal();
       !error && p.has_relative_path() && !std::filesystem::exists(p, error);
       p = p.parent_path()) {
    if (p.has_filename()) created.push_back(p);
  }
  std::filesystem::create_directories(directory, error);
  if (error) ThrowStoreError(label, directory, "cannot create the directory: " + error.message());
  for (const auto& p : created) {
    if (!SyncDirectory(p.parent_path())) {
      ThrowStoreError(label, p.parent_path().string(), std::string("cannot sync the directory: ") + std::strerror(errno));
    }
  }
  *path = (std::filesystem::path(directory) / file_name).string();
  sqlite3* db = nullptr;
  if (sqlite3_open_v2(path->c_str(), &db, SQLITE_OPEN_READWRITE | SQLITE_OPEN_CREATE | SQLITE_OPEN_FULLMUTEX,
                      nullptr) != SQLITE_OK) {
    const std::string message = db ? sqlite3_errmsg(db) : "out of memory";
    sqlite3_close(db);
    ThrowStoreError(label, *path, message);
  }
  sqlite3_busy_timeout(db, 5000);
  try {
    ExecSql(db, label, *path, "PRAGMA journal_mode=WAL");
    ExecSql(db, label, *path, (std::string("PRAGMA synchronous=") + synchronous).c_str());
  } catch (...) {
    sqlite3_close(db);
    throw;
  }
  return db;
}

}  // namespace graspsim
