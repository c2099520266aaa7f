// Shared helpers of the C++ suites.
#pragma once

#include <filesystem>
#include <initializer_list>
#include <random>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "core/error.h"
#include "world/scene_journal.h"

namespace graspsim::test_util {

// Runs `fn`, expects an Error with `code` whose message contains every string in `parts`.
template <typename Fn>
void ExpectError(Fn&& fn, ErrorCode code, std::initializer_list<const char*> parts) {
  try {
    fn();
    ADD_FAILURE() << "no error thrown";
  } catch (const Error& error) {
    EXPECT_EQ(error.code(), code) << error.what();
    for (const char* part : parts) {
      EXPECT_NE(std::string(error.what()).find(part), std::string::npos) << "'" << part << "' not in: " << error.what();
    }
  }
}

// A fresh directory under the system's temporary directory, removed with everything in it at the end of the
// scope. `create`: made now; false leaves it to the code under test (which a test may then check).
class TempDir {
 public:
  explicit TempDir(const std::string& prefix, bool create = true) {
    std::random_device random;
    path_ = std::filesystem::temp_directory_path() /
            ("graspsim-" + prefix + "-" + std::to_string(random()) + std::to_string(random()));
    if (create) std::filesystem::create_directories(path_);
  }
  ~TempDir() { std::filesystem::remove_all(path_); }
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;
  std::string str() const { return path_.string(); }
  const std::filesystem::path& path() const { return path_; }

 private:
  std::filesystem::path path_;
};

// A scene journal that keeps the simulated times of the checkpoints it was handed (a SceneChanged without an op).
class CheckpointJournal : public SceneJournal {
 public:
  void SceneCreated(const std::string&, const std::string&, uint64_t) override {}
  void SceneDeleted(const std::string&) override {}
  void SceneChanged(const std::string&, const SceneOp* op, const SceneState& state, uint64_t) override {
    if (!op) checkpoint_times.push_back(state.time);
  }
  std::vector<double> checkpoint_times;
};

}  // namespace graspsim::test_util
