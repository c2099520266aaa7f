// Shared by the libFuzzer targets of tests/fuzz (docs/fuzzing.md).
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "core/error.h"

namespace graspsim::fuzz {

// The robot-file targets' one "uploaded" mesh, meshes/tetra.stl: a tetrahedron, so inputs that name it reach the
// mesh path.
inline const std::string kTetraStl =
    "solid t\n"
    " facet normal 0 0 -1\n  outer loop\n   vertex 0 0 0\n   vertex 0 1 0\n   vertex 1 0 0\n  endloop\n endfacet\n"
    " facet normal 0 -1 0\n  outer loop\n   vertex 0 0 0\n   vertex 1 0 0\n   vertex 0 0 1\n  endloop\n endfacet\n"
    " facet normal -1 0 0\n  outer loop\n   vertex 0 0 0\n   vertex 0 0 1\n   vertex 0 1 0\n  endloop\n endfacet\n"
    " facet normal 1 1 1\n  outer loop\n   vertex 1 0 0\n   vertex 0 1 0\n   vertex 0 0 1\n  endloop\n endfacet\n"
    "endsolid t\n";

// Runs `f` on one input. graspsim::Error is the expected answer to bad input (the RPC layer maps it to a status
// code naming the field); any other exception escapes to libFuzzer, which reports it as a crash: the server would
// answer INTERNAL, which the design rules out for bad input.
template <class F>
void Rejects(F&& f) {
  try {
    f();
  } catch (const graspsim::Error&) {
  }
}

// A broken invariant of a decoder's own output: abort with a message, so libFuzzer saves the input.
[[noreturn]] inline void Broken(const char* what) {
  std::fprintf(stderr, "fuzz invariant broken: %s\n", what);
  std::abort();
}

inline std::string Text(const uint8_t* data, size_t size) { return std::string(reinterpret_cast<const char*>(data), size); }

}  // namespace graspsim::fuzz
