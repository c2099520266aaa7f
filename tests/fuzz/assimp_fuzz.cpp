// Assimp itself, in this process (world/mesh_import.h ImportMeshInProcess: what graspsim-mesh-import runs), to
// hunt Assimp's own crashes: it finds them within seconds (docs/fuzzing.md, "Found"; tests/fuzz/regressions/
// mesh_*), which is why the server parses meshes in a child process. Not part of `make fuzz-smoke`; run it with
// -fork=1 -ignore_crashes=1 to collect more than one. Input as mesh_fuzz: the first byte picks the extension.
#include "core/mesh.h"
#include "fuzz_common.h"
#include "world/mesh_import.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size < 1) return 0;
  static const char* const kExtensions[] = {"stl", "obj", "ply", "dae"};
  const std::string path = std::string("meshes/fuzz.") + kExtensions[data[0] % 4];
  const std::string bytes = graspsim::fuzz::Text(data + 1, size - 1);
  graspsim::Limits limits;
  limits.max_triangles_per_mesh = 100'000;
  graspsim::fuzz::Rejects([&] {
    const graspsim::TriangleMesh mesh =
        graspsim::ImportMeshInProcess("geometry.mesh_file", path, bytes, graspsim::Vec3(1, 1, 1), limits);
    try {
      graspsim::ValidateMesh(mesh, "mesh", limits.max_triangles_per_mesh);
    } catch (const graspsim::Error&) {
      graspsim::fuzz::Broken("ImportMeshInProcess returned a mesh that ValidateMesh rejects");
    }
  });
  return 0;
}
