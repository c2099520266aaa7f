// URDF loading (import/robot_import.h: urdfdom + graspsim's checks), as AddRobot runs it on a client's text: with
// the default options (the repairs of import/urdf_repairs.cpp and the inertia rules) and strictly.
// The input is the URDF text. One mesh file is "uploaded": meshes/tetra.stl, a tetrahedron, so inputs that name
// it reach the mesh path (package:// and file:// prefixes are stripped by the loader).
#include "fuzz_common.h"
#include "import/robot_import.h"
#include "world/loaders.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string text = graspsim::fuzz::Text(data, size);
  const graspsim::FileLookup files = [](const std::string& path) -> const std::string* {
    return path == "meshes/tetra.stl" ? &graspsim::fuzz::kTetraStl : nullptr;
  };
  graspsim::Limits limits;
  limits.max_triangles_per_mesh = 100'000;
  graspsim::fuzz::Rejects([&] { graspsim::ImportUrdf(text, files, graspsim::ImportOptions(), limits); });
  graspsim::fuzz::Rejects([&] { graspsim::LoadUrdf(text, files, limits); });
  return 0;
}
