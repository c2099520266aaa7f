#include "core/sqlite_file.h"

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <vector>

#include <sqlite3.h>

#include "core/durable_files.h"
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

sqlite3* OpenStoreFile(const std::string& label, const std::string& directory, const std::string& file_name,
                       const char* synchronous, std::string* path) {
  // The directories created here (the data directory on a first start) must outlive a power cut with the database
  // in them: SQLite syncs its files' own directory, never the ones above it (tests/bench/power_cut.py found this).
  CreateDirectoriesDurably(label, directory);
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
