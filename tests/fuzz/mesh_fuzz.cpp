// Mesh loading (world/loaders.h LoadMeshFile: Assimp's STL, OBJ, PLY and COLLADA importers and graspsim's checks),
// as an uploaded mesh file or an inline Geometry.mesh_file reaches it. The first byte picks the extension (the
// loader takes the format from it), the rest is the file. A mesh that loads must be a valid mesh.
#include "core/mesh.h"
#include "fuzz_common.h"
#include "world/loaders.h"

namespace {

// KNOWN OPEN (docs/fuzzing.md, "Found"): Assimp 5.2.5's PLY importer reads past its buffer on a header that
// holds a NUL byte or never reaches end_header (tests/fuzz/regressions/mesh_ply_unterminated_header crashes the
// server). Until LoadMeshFile refuses such a header itself, the target skips these inputs so it can look for
// the next bug; remove this filter with that fix.
bool KnownOpenPly(const std::string& bytes) {
  const size_t end = bytes.find("end_header");
  return end == std::string::npos || bytes.find('\0') < end;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size < 1) return 0;
  static const char* const kExtensions[] = {"stl", "obj", "ply", "dae"};
  const std::string path = std::string("meshes/fuzz.") + kExtensions[data[0] % 4];
  const std::string bytes = graspsim::fuzz::Text(data + 1, size - 1);
  if (data[0] % 4 == 2 && KnownOpenPly(bytes)) return 0;
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
