#include "core/durable_files.h"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <vector>

#include "core/error.h"

namespace graspsim {
namespace {

[[noreturn]] void ThrowSystem(const std::string& what, const std::string& path) {
  throw Error(ErrorCode::kInternal, "cannot " + what + " '" + path + "': " + std::strerror(errno));
}

}  // namespace

bool SyncDirectory(const std::filesystem::path& directory) {
  const int fd = ::open(directory.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (fd < 0) return false;
  const bool ok = ::fsync(fd) == 0;
  ::close(fd);
  return ok;
}

void CreateDirectoriesDurably(const std::string& label, const std::filesystem::path& directory) {
  std::error_code error;
  std::vector<std::filesystem::path> created;
  for (auto p = std::filesystem::absolute(directory, error).lexically_normal();
       !error && p.has_relative_path() && !std::filesystem::exists(p, error); p = p.parent_path()) {
    if (p.has_filename()) created.push_back(p);
  }
  std::filesystem::create_directories(directory, error);
  if (error) {
    throw Error(ErrorCode::kFailedPrecondition,
                label + directory.string() + ": cannot create the directory: " + error.message());
  }
  for (const auto& p : created) {
    if (!SyncDirectory(p.parent_path())) {
      throw Error(ErrorCode::kFailedPrecondition, label + p.parent_path().string() +
                                                      ": cannot sync the directory: " + std::strerror(errno));
    }
  }
}

void SyncFile(std::FILE* file, const std::string& path) {
  if (std::fflush(file) != 0 || ::fsync(::fileno(file)) != 0) ThrowSystem("sync", path);
}

void ReplaceFileDurably(const std::filesystem::path& path, const std::string& contents) {
  const std::string temporary = path.string() + ".tmp";
  std::FILE* file = std::fopen(temporary.c_str(), "wb");
  if (!file) ThrowSystem("create", temporary);
  const bool written = std::fwrite(contents.data(), 1, contents.size(), file) == contents.size();
  const int saved = errno;
  bool synced = written;
  if (written) {
    synced = std::fflush(file) == 0 && ::fsync(::fileno(file)) == 0;
  }
  const int sync_error = errno;
  std::fclose(file);
  if (!written) {
    errno = saved;
    ThrowSystem("write", temporary);
  }
  if (!synced) {
    errno = sync_error;
    ThrowSystem("sync", temporary);
  }
  std::error_code error;
  std::filesystem::rename(temporary, path, error);
  if (error) throw Error(ErrorCode::kInternal, "cannot rename '" + temporary + "': " + error.message());
  if (!SyncDirectory(path.parent_path())) ThrowSystem("sync the directory of", path.string());
}

}  // namespace graspsim
