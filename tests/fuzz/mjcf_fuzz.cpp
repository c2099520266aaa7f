// MJCF loading (import/robot_import.h ImportMjcf: tinyxml2 + the MJCF compiler's rules), as AddRobot runs it on a
// client's text. The input is the MJCF text. Two files are "uploaded": meshes/tetra.stl, a tetrahedron, so inputs
// that name it reach the mesh path, and part.xml, a body, so <include file="part.xml"/> reaches the include path.
#include "fuzz_common.h"
#include "import/robot_import.h"

namespace {


const std::string kPart =
    "<mujoco><body name=\"part\" pos=\"0 0 0.1\"><joint type=\"ball\"/><geom type=\"capsule\" size=\"0.01 0.02\"/>"
    "</body></mujoco>";

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string text = graspsim::fuzz::Text(data, size);
  const graspsim::FileLookup files = [](const std::string& path) -> const std::string* {
    if (path == "meshes/tetra.stl") return &graspsim::fuzz::kTetraStl;
    if (path == "part.xml") return &kPart;
    return nullptr;
  };
  graspsim::Limits limits;
  limits.max_triangles_per_mesh = 100'000;
  limits.max_bodies_per_scene = 256;
  graspsim::fuzz::Rejects([&] { graspsim::ImportMjcf(text, files, graspsim::ImportOptions(), limits); });
  return 0;
}
