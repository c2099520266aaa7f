// Assimp itself, in this process (world/mesh_import.h ImportMeshInProcess: what graspsim-mesh-import runs), to
// hunt Assimp's own crashes: it finds them within seconds (docs/fuzzing.md, "Found"; tests/fuzz/regressions/
// mesh_*), which is why the server parses meshes in a child process. Not part of `make fuzz-smoke`; run it with
// -fork=1 -ignore_crashes=1 to collect more than one. Input as mesh_fuzz: the first byte picks the extension.
#include "mesh_input.h"
#include "world/mesh_import.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  graspsim::fuzz::MeshFile(data, size, graspsim::ImportMeshInProcess, "ImportMeshInProcess returned a mesh that ValidateMesh rejects");
  return 0;
}
