#include "motion/sphere_kernel.h"

#include <cstdlib>
#include <cstring>

namespace graspsim::motion::kernel {
#if defined(__x86_64__)
namespace {
// Decided once: the AVX2 build runs only where the CPU has AVX2 and FMA (GRASPSIM_KERNEL=generic forces the other,
// for tests that compare the two).
bool UseAvx2() {
  static const bool use = [] {
    const char* forced = std::getenv("GRASPSIM_KERNEL");
    if (forced && std::strcmp(forced, "generic") == 0) return false;
    __builtin_cpu_init();
    return __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma");
  }();
  return use;
}
}  // namespace
#endif

uint32_t CollidingLanes(const Model& model, const float* q, const float* inflate, float* scratch, bool stop_at_first) {
#if defined(__x86_64__)
  if (UseAvx2()) return avx2::CollidingLanes(model, q, inflate, scratch, stop_at_first);
#endif
  return generic::CollidingLanes(model, q, inflate, scratch, stop_at_first);
}

const char* KernelIsa() {
#if defined(__x86_64__)
  if (UseAvx2()) return "avx2";
  return "sse2";
#else
  return "generic";
#endif
}

}  // namespace graspsim::motion::kernel
