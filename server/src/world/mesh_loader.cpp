// Mesh files → TriangleMesh with Assimp, read from memory (uploads never touch the disk). This runs in
// graspsim-mesh-import, never in the server (world/mesh_import.h says why).
//
// Conventions, chosen to match what ROS tools (RViz, MoveIt's geometric_shapes) do with the same files:
// - COLLADA <unit meter="..."> is honoured: Assimp 5.2 folds it into the root node's transform, so a DAE drawn in
//   millimetres comes out in metres.
// - COLLADA <up_axis> is ignored: Assimp would otherwise rotate Z_UP files into Y_UP, but URDF meshes are drawn in
//   the link frame, which is already Z-up.
// - Node transforms are applied and every mesh instance of the scene graph is merged into one mesh, so a part
//   instanced twice appears twice.
#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include <assimp/Importer.hpp>
#include <assimp/MemoryIOWrapper.h>
#include <assimp/config.h>
#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include "core/error.h"
#include "core/validate.h"
#include "world/loaders.h"
#include "world/mesh_import.h"

namespace graspsim {
namespace {

constexpr std::array<std::string_view, 4> kSupportedExtensions = {"stl", "obj", "ply", "dae"};
constexpr std::string_view kSupportedList = ".stl, .obj, .ply, .dae";

// The extension after the last '.' of the file name (not of a directory), lower-case; empty if none.
std::string LowerCaseExtension(const std::string& path) {
  const size_t name_start = path.find_last_of('/') == std::string::npos ? 0 : path.find_last_of('/') + 1;
  const size_t dot = path.find_last_of('.');
  if (dot == std::string::npos || dot < name_start) return "";
  std::string extension = path.substr(dot + 1);
  std::transform(extension.begin(), extension.end(), extension.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return extension;
}

// One placement of an aiMesh in the file's root frame.
struct MeshInstance {
  const aiMesh* mesh;
  aiMatrix4x4 to_root;
};

// Walks the node graph without recursion (a hostile file may nest nodes arbitrarily deep).
std::vector<MeshInstance> CollectMeshInstances(const aiScene& scene) {
  std::vector<MeshInstance> instances;
  std::vector<std::pair<const aiNode*, aiMatrix4x4>> pending = {{scene.mRootNode, scene.mRootNode->mTransformation}};
  while (!pending.empty()) {
    const auto [node, to_root] = pending.back();
    pending.pop_back();
    for (unsigned i = 0; i < node->mNumMeshes; ++i) {
      instances.push_back({scene.mMeshes[node->mMeshes[i]], to_root});
    }
    for (unsigned i = 0; i < node->mNumChildren; ++i) {
      const aiNode* child = node->mChildren[i];
      pending.emplace_back(child, to_root * child->mTransformation);
    }
  }
  return instances;
}

size_t CountTriangles(const aiMesh& mesh) {
  return static_cast<size_t>(
      std::count_if(mesh.mFaces, mesh.mFaces + mesh.mNumFaces, [](const aiFace& f) { return f.mNumIndices == 3; }));
}

// Appends one instance: vertices mapped to the root frame and scaled per axis. A mirroring transform (negative
// determinant) would turn the triangles inside out, so their winding is reversed to keep it counter-clockwise
// seen from outside.
void AppendInstance(const MeshInstance& instance, const Vec3& scale, TriangleMesh* merged) {
  const aiMesh& mesh = *instance.mesh;
  const uint32_t first_vertex = static_cast<uint32_t>(merged->vertices.size());
  for (unsigned v = 0; v < mesh.mNumVertices; ++v) {
    const aiVector3D p = instance.to_root * mesh.mVertices[v];
    merged->vertices.emplace_back(static_cast<float>(p.x * scale.x()), static_cast<float>(p.y * scale.y()),
                                  static_cast<float>(p.z * scale.z()));
  }
  const bool mirrored = instance.to_root.Determinant() * scale.prod() < 0;
  for (unsigned f = 0; f < mesh.mNumFaces; ++f) {
    const aiFace& face = mesh.mFaces[f];
    if (face.mNumIndices != 3 || face.mIndices[0] >= mesh.mNumVertices || face.mIndices[1] >= mesh.mNumVertices ||
        face.mIndices[2] >= mesh.mNumVertices) {
      continue;
    }
    std::array<uint32_t, 3> triangle = {first_vertex + face.mIndices[0], first_vertex + face.mIndices[1],
                                        first_vertex + face.mIndices[2]};
    if (mirrored) std::swap(triangle[1], triangle[2]);
    merged->triangles.push_back(triangle);
  }
}

}  // namespace

void CheckMeshFileRequest(const std::string& field, const std::string& path, std::string_view bytes,
                          const Vec3& scale) {
  const std::string extension = LowerCaseExtension(path);
  if (std::find(kSupportedExtensions.begin(), kSupportedExtensions.end(), extension) ==
      kSupportedExtensions.end()) {
    ThrowInvalidArgument(field + ": mesh file '" + path + "' has an unsupported format; supported: " +
                         std::string(kSupportedList));
  }
  CheckFinite(field + ": scale", scale);
  if ((scale.array() == 0).any()) {
    ThrowInvalidArgument(field + ": scale of mesh file '" + path + "' has a zero component");
  }
  if (bytes.empty()) ThrowInvalidArgument(field + ": mesh file '" + path + "' is empty");
}

TriangleMesh ImportMeshInProcess(const std::string& field, const std::string& path, std::string_view bytes,
                                 const Vec3& scale, const Limits& limits) {
  CheckMeshFileRequest(field, path, bytes, scale);
  const std::string extension = LowerCaseExtension(path);

  // No DefaultLogger is created, so Assimp logs nowhere (its NullLogger) and never writes to stdout.
  Assimp::Importer importer;
  importer.SetPropertyBool(AI_CONFIG_IMPORT_COLLADA_IGNORE_UP_DIRECTION, true);
  // Points and lines carry no surface; dropping them keeps stray vertices out of the bounds.
  importer.SetPropertyInteger(AI_CONFIG_PP_SBP_REMOVE, aiPrimitiveType_POINT | aiPrimitiveType_LINE);
  const unsigned flags = aiProcess_Triangulate | aiProcess_JoinIdenticalVertices | aiProcess_SortByPType |
                         aiProcess_ValidateDataStructure;  // rejects out-of-range indices of hostile files
  const aiScene* scene = importer.ReadFileFromMemory(bytes.data(), bytes.size(), flags, extension.c_str());
  // Assimp's OBJ reader marks a mesh with line elements as triangles only, which its own validation then refuses
  // (pybullet_data's samurai_monastry.obj). Without the validation step, SortByPType drops the lines and
  // AppendInstance skips any face index outside its mesh.
  if (scene == nullptr && (std::string(importer.GetErrorString()).find("LINE but") != std::string::npos ||
                           std::string(importer.GetErrorString()).find("POINT but") != std::string::npos)) {
    scene = importer.ReadFileFromMemory(bytes.data(), bytes.size(), flags & ~aiProcess_ValidateDataStructure,
                                        extension.c_str());
  }
  if (scene == nullptr || scene->mRootNode == nullptr || (scene->mFlags & AI_SCENE_FLAGS_INCOMPLETE) != 0) {
    // Assimp names a file read from memory "$$$___magic___$$$.<ext>"; the client knows it by its path.
    std::string reason = importer.GetErrorString();
    const std::string magic_name = AI_MEMORYIO_MAGIC_FILENAME "." + extension;
    if (const size_t at = reason.find(magic_name); at != std::string::npos) reason.replace(at, magic_name.size(), path);
    ThrowInvalidArgument(field + ": mesh file '" + path + "' does not parse as ." + extension + ": " +
                         (reason.empty() ? "the file holds no scene" : reason));
  }

  const std::vector<MeshInstance> instances = CollectMeshInstances(*scene);
  // Count before merging: instancing lets a small file describe more triangles than memory holds.
  size_t triangle_count = 0;
  size_t vertex_count = 0;
  for (const MeshInstance& instance : instances) {
    triangle_count += CountTriangles(*instance.mesh);
    vertex_count += instance.mesh->mNumVertices;
  }
  if (triangle_count > limits.max_triangles_per_mesh) {
    ThrowResourceExhausted(field + ": mesh file '" + path + "' has " + std::to_string(triangle_count) +
                           " triangles, above the limit of " + std::to_string(limits.max_triangles_per_mesh));
  }
  if (vertex_count > UINT32_MAX) {
    ThrowResourceExhausted(field + ": mesh file '" + path + "' has more vertices than 32-bit indices address");
  }

  TriangleMesh merged;
  merged.vertices.reserve(vertex_count);
  merged.triangles.reserve(triangle_count);
  for (const MeshInstance& instance : instances) AppendInstance(instance, scale, &merged);
  ValidateMesh(merged, field + ": mesh file '" + path + "'", limits.max_triangles_per_mesh);
  return merged;
}

}  // namespace graspsim
