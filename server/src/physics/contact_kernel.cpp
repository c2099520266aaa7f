// The contact kernel's dispatch (contact_kernel.h): the AVX2 + FMA build where the CPU has both, else the
// baseline one.
#include "physics/contact_kernel.h"

#include <cstdlib>
#include <cstring>

namespace graspsim::contact_kernel {
#if defined(__x86_64__)
namespace {
// Decided once (GRASPSIM_KERNEL=generic forces the baseline build, for tests that compare the two).
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

void EvaluateRun(const ContactRun& run, bool linearize, double* fx, double* fy, double* fz, double* fn,
                 RunSums* sums) {
#if defined(__x86_64__)
  if (UseAvx2()) return avx2::EvaluateRun(run, linearize, fx, fy, fz, fn, sums);
#endif
  generic::EvaluateRun(run, linearize, fx, fy, fz, fn, sums);
}

void AdvanceRun(const ContactRun& run, const double* fn, double* zx, double* zy, double* zz) {
#if defined(__x86_64__)
  if (UseAvx2()) return avx2::AdvanceRun(run, fn, zx, zy, zz);
#endif
  generic::AdvanceRun(run, fn, zx, zy, zz);
}

const char* ContactKernelIsa() {
#if defined(__x86_64__)
  return UseAvx2() ? "avx2" : "sse2";
#else
  return "generic";
#endif
}

}  // namespace graspsim::contact_kernel
