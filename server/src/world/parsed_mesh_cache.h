// Meshes already parsed, by content: a robot added to a second scene, or loaded again, does not pay for its mesh
// files again (a child process and Assimp per file: ~10 ms each for the Panda's OBJs). Keyed by the SHA-256 of the
// file's bytes with its extension, scale and the triangle limit, so a hit is the same answer the parser would give.
// Process-wide, thread-safe, least recently used entries dropped beyond a memory budget. Internal to world/.
#pragma once

#include <memory>
#include <string>
#include <string_view>

#include "core/math.h"
#include "core/mesh.h"

namespace graspsim {

class ParsedMeshCache {
 public:
  static ParsedMeshCache& Instance();

  static std::string Key(const std::string& path, std::string_view bytes, const Vec3& scale, size_t max_triangles);
  std::shared_ptr<const TriangleMesh> Find(const std::string& key);
  void Put(const std::string& key, std::shared_ptr<const TriangleMesh> mesh);

 private:
  struct State;
  ParsedMeshCache();
  std::unique_ptr<State> state_;
};

}  // namespace graspsim
