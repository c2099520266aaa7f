// SDF loading (import/robot_import.h ImportSdf: libsdformat 12 + graspsim's conversion), as AddRobot runs it on a
// client's text. One mesh file is "uploaded": meshes/tetra.stl, a tetrahedron, so inputs that name it reach the
// mesh path (model://, package:// and file:// prefixes are stripped by the loader).
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
  // One import per input (libsdformat takes tens of ms even for a small text): odd sizes load strictly, with
  // inertia from geometry, the model named "b".
  graspsim::ImportOptions options;
  if (size % 2 == 1) {
    options.strict = true;
    options.model_name = "b";
    options.inertia = graspsim::InertiaSource::kFromGeometry;
  }
  graspsim::fuzz::Rejects([&] { graspsim::ImportSdf(text, files, options, limits); });
  return 0;
}
