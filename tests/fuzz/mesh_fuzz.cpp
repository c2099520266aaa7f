// Mesh loading as the server does it (world/loaders.h LoadMeshFile): the file is parsed by Assimp (STL, OBJ, PLY,
// COLLADA) in a child process, graspsim-mesh-import (world/mesh_import.h), found beside this binary. The first
// byte picks the extension (the loader takes the format from it), the rest is the file. Whatever the child does
// (crash, abort, run out of memory or time), LoadMeshFile must answer a valid mesh or an Error; a mesh that
// loads must pass ValidateMesh. Assimp's own crashes are hunted in-process by assimp_fuzz.
#include "mesh_input.h"
#include "world/loaders.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  graspsim::fuzz::MeshFile(data, size, graspsim::LoadMeshFile, "LoadMeshFile returned a mesh that ValidateMesh rejects");
  return 0;
}
