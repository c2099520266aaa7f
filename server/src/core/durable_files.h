// Files and directories that survive a power cut, not only a crash of the process: data reaches the disk at a
// file's fsync, a name (a new file's, a new directory's, a rename's) at its directory's fsync. What the stores
// and the recordings share; tests/bench/power_cut.py checks both against a simulated power cut.
#pragma once

#include <cstdio>
#include <filesystem>
#include <string>

namespace graspsim {

// fsync of a directory. False (errno set) when it cannot be opened or synced.
bool SyncDirectory(const std::filesystem::path& directory);

// Creates `directory` and its missing parents, then syncs the parent of each one created, so that the whole
// path outlives a power cut. Throws Error(kFailedPrecondition) "<label><path>: <what>".
void CreateDirectoriesDurably(const std::string& label, const std::filesystem::path& directory);

// Flushes `file` (stdio's buffer, then the kernel's to the disk). Throws Error(kInternal) naming `path`.
void SyncFile(std::FILE* file, const std::string& path);

// Writes `contents` to `path` whole or not at all, durably: a temporary file beside it, synced, renamed over it,
// then the directory synced. Throws Error(kInternal) naming `path`.
void ReplaceFileDurably(const std::filesystem::path& path, const std::string& contents);

}  // namespace graspsim
