#include "world/parsed_mesh_cache.h"

#include <list>
#include <mutex>
#include <unordered_map>

#include "core/format.h"
#include "core/sha256.h"

namespace graspsim {
namespace {

// 256 MiB of vertices and triangles: about 10 million triangles, far more than a lab's robots and objects.
constexpr size_t kBudgetBytes = size_t{256} << 20;

size_t SizeOf(const TriangleMesh& mesh) {
  return mesh.vertices.size() * sizeof(mesh.vertices[0]) + mesh.triangles.size() * sizeof(mesh.triangles[0]);
}

}  // namespace

struct ParsedMeshCache::State {
  std::mutex mutex;
  std::list<std::pair<std::string, std::shared_ptr<const TriangleMesh>>> recent;  // most recently used first
  std::unordered_map<std::string, decltype(recent)::iterator> index;
  size_t bytes = 0;
};

ParsedMeshCache::ParsedMeshCache() : state_(std::make_unique<State>()) {}

ParsedMeshCache& ParsedMeshCache::Instance() {
  static ParsedMeshCache* const cache = new ParsedMeshCache();  // never destroyed: used until exit
  return *cache;
}

std::string ParsedMeshCache::Key(const std::string& path, std::string_view bytes, const Vec3& scale,
                                 size_t max_triangles) {
  const size_t dot = path.find_last_of('.');
  const std::string extension = dot == std::string::npos ? "" : path.substr(dot);
  return Sha256Hex(bytes) + extension + " " + FormatNumber(scale.x()) + " " + FormatNumber(scale.y()) + " " +
         FormatNumber(scale.z()) + " " + std::to_string(max_triangles);
}

std::shared_ptr<const TriangleMesh> ParsedMeshCache::Find(const std::string& key) {
  std::lock_guard<std::mutex> lock(state_->mutex);
  const auto it = state_->index.find(key);
  if (it == state_->index.end()) return nullptr;
  state_->recent.splice(state_->recent.begin(), state_->recent, it->second);
  return it->second->second;
}

void ParsedMeshCache::Put(const std::string& key, std::shared_ptr<const TriangleMesh> mesh) {
  const size_t size = SizeOf(*mesh);
  if (size > kBudgetBytes / 4) return;  // one huge mesh would push out everything else
  std::lock_guard<std::mutex> lock(state_->mutex);
  if (state_->index.count(key)) return;
  state_->recent.emplace_front(key, std::move(mesh));
  state_->index[key] = state_->recent.begin();
  state_->bytes += size;
  while (state_->bytes > kBudgetBytes) {
    state_->bytes -= SizeOf(*state_->recent.back().second);
    state_->index.erase(state_->recent.back().first);
    state_->recent.pop_back();
  }
}

}  // namespace graspsim
