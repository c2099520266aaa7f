// The input of the mesh targets (mesh_fuzz, assimp_fuzz): the first byte picks the extension (the loaders take
// the format from it), the rest is the file. `load` is LoadMeshFile or ImportMeshInProcess; a mesh it returns
// must pass ValidateMesh, any other answer must be an Error.
#pragma once

#include <string>

#include "core/limits.h"
#include "core/math.h"
#include "core/mesh.h"
#include "fuzz_common.h"

namespace graspsim::fuzz {

template <class Load>
void MeshFile(const uint8_t* data, size_t size, Load&& load, const char* broken_message) {
  if (size < 1) return;
  static const char* const kExtensions[] = {"stl", "obj", "ply", "dae"};
  const std::string path = std::string("meshes/fuzz.") + kExtensions[data[0] % 4];
  const std::string bytes = Text(data + 1, size - 1);
  Limits limits;
  limits.max_triangles_per_mesh = 100'000;
  Rejects([&] {
    const TriangleMesh mesh = load("geometry.mesh_file", path, bytes, Vec3(1, 1, 1), limits);
    try {
      ValidateMesh(mesh, "mesh", limits.max_triangles_per_mesh);
    } catch (const Error&) {
      Broken(broken_message);
    }
  });
}

}  // namespace graspsim::fuzz
