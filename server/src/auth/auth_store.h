// What the auth RPCs change survives restarts: tokens added or revoked through AuthService, the owners of
// scenes, scene shares and device grants, in <directory>/auth.sqlite (WAL, synchronous=FULL). The scene store
// (persistence/) keeps the scenes themselves; this file keeps only who may touch them.
#pragma once

#include <functional>
#include <string>
#include <vector>

struct sqlite3;

namespace graspsim::auth {

class AuthStore {
 public:
  // Opens or creates the database; throws Error(kFailedPrecondition) naming the file when it cannot.
  explicit AuthStore(const std::string& directory);
  ~AuthStore();
  AuthStore(const AuthStore&) = delete;
  AuthStore& operator=(const AuthStore&) = delete;

  const std::string& path() const { return path_; }
  // One statement with text parameters ?1, ?2, ...; throws on failure.
  void Run(const char* sql, const std::vector<std::string>& params);
  // Calls row(columns) for every row of a query without parameters.
  void ForEach(const char* sql, const std::function<void(const std::vector<std::string>&)>& row);

 private:
  std::string path_;
  sqlite3* db_ = nullptr;
};

}  // namespace graspsim::auth
