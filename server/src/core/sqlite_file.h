// What every SQLite store of the server (grasp sets, scenes, tokens) does the same way: create its directory,
// open its file read-write (created when absent; serialized, as several threads use it), wait up to 5 s for a
// second server on the same directory instead of failing, journal in WAL mode with the store's `synchronous`
// level. Errors are Error(kFailedPrecondition, "<label><path>: <what>"): the label says which store or flag.
#pragma once

#include <string>

struct sqlite3;

namespace graspsim {

[[noreturn]] void ThrowStoreError(const std::string& label, const std::string& path, const std::string& what);

// Returns the open handle (the caller closes it) and sets *path to <directory>/<file_name>. The first statement
// reads the file's header, so a file that is not a database is refused here and left as it is.
sqlite3* OpenStoreFile(const std::string& label, const std::string& directory, const std::string& file_name,
                       const char* synchronous, std::string* path);

// Runs statements without results; ThrowStoreError on failure.
void ExecSql(sqlite3* db, const std::string& label, const std::string& path, const char* sql);

}  // namespace graspsim
