// Mesh files are parsed in a child process, graspsim-mesh-import, never in the server's own.
//
// Why: Assimp 5.2 crashes (SEGV), aborts (ai_assert) and allocates gigabytes on hostile files of a few hundred
// bytes (tests/fuzz/regressions/mesh_*, docs/fuzzing.md), and a mesh file is whatever a client uploads. In a
// child such a file costs only the child: the request answers INVALID_ARGUMENT naming the file, and the server
// and every scene go on. The child runs under an address-space limit and a deadline (10 s + 1 s per MiB).
// The price is one posix_spawn and Assimp's start-up per file (a few ms; a 200k-triangle STL parses in ~0.3 s).
// LoadMeshFile (world/loaders.h) is the one entry point for the rest of the server.
#pragma once

#include <string>
#include <string_view>

#include "core/limits.h"
#include "core/math.h"
#include "core/mesh.h"

namespace graspsim {

// The checks that need no parsing (extension, scale, an empty file), made before a child is started.
void CheckMeshFileRequest(const std::string& field, const std::string& path, std::string_view bytes,
                          const Vec3& scale);

// Assimp in this process. Only graspsim-mesh-import and the fuzz target that hunts Assimp's own crashes call it.
TriangleMesh ImportMeshInProcess(const std::string& field, const std::string& path, std::string_view bytes,
                                 const Vec3& scale, const Limits& limits);

// The child's side: reads one request from `in_fd` until end of file, writes the answer to `out_fd`, returns
// the process's exit code. main() of graspsim-mesh-import (app/mesh_import_main.cpp).
int ServeMeshImport(int in_fd, int out_fd);

// Where graspsim-mesh-import is: $GRASPSIM_MESH_IMPORT when set, else beside the running executable.
std::string MeshImporterPath();

}  // namespace graspsim
