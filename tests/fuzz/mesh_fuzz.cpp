// Mesh loading as the server does it (world/loaders.h LoadMeshFile): the file is parsed by Assimp (STL, OBJ, PLY,
// COLLADA) in a child process, graspsim-mesh-import (world/mesh_import.h), found beside this binary. The first
// byte picks the extension (the loader takes the format from it), the rest is the file. Whatever the child does
// (crash, abort, run out of memory or time), LoadMeshFile must answer a valid mesh or an Error; a mesh that
// loads must pass ValidateMesh. Assimp's own crashes are hunted in-process by assimp_fuzz.
#include "core/mesh.h"
#include "fuzz_common.h"
#include "world/loaders.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size < 1) return 0;
  static const char* const kExtensions[] = {"stl", "obj", "ply", "dae"};
  const std::string path = std::string("meshes/fuzz.") + kExtensions[data[0] % 4];
  const std::string bytes = graspsim::fuzz::Text(data + 1, size - 1);
  graspsim::Limits limits;
  limits.max_triangles_per_mesh = 100'000;
  graspsim::fuzz::Rejects([&] {
    const graspsim::TriangleMesh mesh =
        graspsim::LoadMeshFile("geometry.mesh_file", path, bytes, graspsim::Vec3(1, 1, 1), limits);
    try {
      graspsim::ValidateMesh(mesh, "mesh", limits.max_triangles_per_mesh);
    } catch (const graspsim::Error&) {
      graspsim::fuzz::Broken("LoadMeshFile returned a mesh that ValidateMesh rejects");
    }
  });
  return 0;
}
