// Shared by the libFuzzer targets of tests/fuzz (docs/fuzzing.md).
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "core/error.h"

namespace graspsim::fuzz {

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
