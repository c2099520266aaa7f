#include "auth/auth_store.h"

#include <filesystem>

#include <sqlite3.h>

#include "core/error.h"
#include "core/sqlite_file.h"

namespace graspsim::auth {
namespace {

constexpr char kLabel[] = "--auth-data-dir: ";

[[noreturn]] void Fail(const std::string& path, const std::string& what) { ThrowStoreError(kLabel, path, what); }

struct Statement {
  sqlite3_stmt* stmt = nullptr;
  ~Statement() { sqlite3_finalize(stmt); }
};

}  // namespace

AuthStore::AuthStore(const std::string& directory) {
  db_ = OpenStoreFile(kLabel, directory, "auth.sqlite", "FULL", &path_);
  // Owner-only: the file holds token hashes.
  std::error_code error;
  std::filesystem::permissions(path_, std::filesystem::perms::owner_read | std::filesystem::perms::owner_write,
                               std::filesystem::perm_options::replace, error);
  for (const char* sql : {"CREATE TABLE IF NOT EXISTS tokens (name TEXT PRIMARY KEY, role TEXT NOT NULL, hash TEXT NOT NULL)",
                          "CREATE TABLE IF NOT EXISTS revoked (name TEXT PRIMARY KEY)",
                          "CREATE TABLE IF NOT EXISTS scenes (scene_id TEXT PRIMARY KEY, owner TEXT NOT NULL)",
                          "CREATE TABLE IF NOT EXISTS shares (scene_id TEXT NOT NULL, name TEXT NOT NULL,"
                          " PRIMARY KEY (scene_id, name))",
                          "CREATE TABLE IF NOT EXISTS grants (device_id TEXT NOT NULL, name TEXT NOT NULL,"
                          " PRIMARY KEY (device_id, name))"}) {
    try {
      Run(sql, {});
    } catch (...) {
      sqlite3_close(db_);
      db_ = nullptr;
      throw;
    }
  }
}

AuthStore::~AuthStore() { sqlite3_close(db_); }

void AuthStore::Run(const char* sql, const std::vector<std::string>& params) {
  Statement s;
  if (sqlite3_prepare_v2(db_, sql, -1, &s.stmt, nullptr) != SQLITE_OK) Fail(path_, sqlite3_errmsg(db_));
  for (size_t i = 0; i < params.size(); ++i) {
    sqlite3_bind_text(s.stmt, static_cast<int>(i + 1), params[i].data(), static_cast<int>(params[i].size()),
                      SQLITE_TRANSIENT);
  }
  int rc;
  while ((rc = sqlite3_step(s.stmt)) == SQLITE_ROW) {
  }
  if (rc != SQLITE_DONE) Fail(path_, sqlite3_errmsg(db_));
}

void AuthStore::ForEach(const char* sql, const std::function<void(const std::vector<std::string>&)>& row) {
  Statement s;
  if (sqlite3_prepare_v2(db_, sql, -1, &s.stmt, nullptr) != SQLITE_OK) Fail(path_, sqlite3_errmsg(db_));
  int rc;
  while ((rc = sqlite3_step(s.stmt)) == SQLITE_ROW) {
    std::vector<std::string> columns(sqlite3_column_count(s.stmt));
    for (size_t i = 0; i < columns.size(); ++i) {
      const auto* text = sqlite3_column_text(s.stmt, static_cast<int>(i));
      if (text) columns[i].assign(reinterpret_cast<const char*>(text), sqlite3_column_bytes(s.stmt, static_cast<int>(i)));
    }
    row(columns);
  }
  if (rc != SQLITE_DONE) Fail(path_, sqlite3_errmsg(db_));
}

}  // namespace graspsim::auth
