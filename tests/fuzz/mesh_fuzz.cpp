// Mesh loading (world/loaders.h LoadMeshFile: Assimp's STL, OBJ, PLY and COLLADA importers and graspsim's checks),
// as an uploaded mesh file or an inline Geometry.mesh_file reaches it. The first byte picks the extension (the
// loader takes the format from it), the rest is the file. A mesh that loads must be a valid mesh.
// Assimp 5.2.5 itself crashes, aborts and runs out of memory on small hostile files (docs/fuzzing.md, "Found";
// tests/fuzz/regressions/mesh_*): until LoadMeshFile no longer runs Assimp on untrusted bytes in the server's
// process, `make fuzz-smoke` runs this target over its seed corpus only, and a longer run needs
// -fork=1 -ignore_crashes=1 to get past them.
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
