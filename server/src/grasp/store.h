// Grasp sets that survive requests and restarts: an embedded SQLite database (<directory>/grasp_sets.sqlite, WAL
// journal so readers never wait for a writer). A set's key is the SHA-256 of everything that decides it: the
// hand's URDF, the object mesh's bytes, the obstacles, the candidate and simulation parameters, and the number
// of grasps kept; the same request finds the stored set instead of planning again.
#pragma once

#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "core/mesh.h"
#include "grasp/planner.h"

struct sqlite3;

namespace graspsim::grasp {

// SHA-256 (hex) of a mesh's float32 vertices and uint32 indices, little-endian, as sent on the wire.
std::string MeshHash(const TriangleMesh& mesh);

// The key of a grasp set, and the canonical text of its parameters (stored beside it, for people).
struct GraspSetKey {
  std::string key;
  std::string params_text;
};
GraspSetKey MakeGraspSetKey(const std::string& hand, const std::string& mesh_hash,
                            const std::vector<ObstacleBox>& obstacles, const CandidateParams& candidates,
                            const ClosingParams& simulation, size_t max_grasps);

struct StoredGraspSet {
  std::string key, hand, mesh_hash, params_text;
  double created_unix = 0;  // s since 1970
  GraspSet set;
};

class GraspStore {
 public:
  // Creates the directory and the database when missing. Throws Error(kFailedPrecondition) naming the path
  // when it cannot.
  explicit GraspStore(const std::string& directory);
  ~GraspStore();
  GraspStore(const GraspStore&) = delete;
  GraspStore& operator=(const GraspStore&) = delete;

  std::optional<StoredGraspSet> Find(const std::string& key) const;
  // Replaces a set of the same key.
  void Put(const StoredGraspSet& stored);
  const std::string& path() const { return path_; }

 private:
  std::string path_;
  sqlite3* db_ = nullptr;
  mutable std::mutex mutex_;  // one connection, serialised: sets are written once and read rarely
};

}  // namespace graspsim::grasp
