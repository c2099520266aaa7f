// The contact kernel's dispatch (contact_kernel.h): the AVX2 + FMA build where the CPU has both, else the
// baseline one.
#include "physics/contact_kernel.h"

#include "core/cpu_dispatch.h"

namespace graspsim::contact_kernel {

void EvaluateRun(const ContactRun& run, bool linearize, double* fx, double* fy, double* fz, double* fn,
                 RunSums* sums) {
#if defined(__x86_64__)
  if (UseAvx2Kernels()) return avx2::EvaluateRun(run, linearize, fx, fy, fz, fn, sums);
#endif
  generic::EvaluateRun(run, linearize, fx, fy, fz, fn, sums);
}

void AdvanceRun(const ContactRun& run, const double* fn, double* zx, double* zy, double* zz) {
#if defined(__x86_64__)
  if (UseAvx2Kernels()) return avx2::AdvanceRun(run, fn, zx, zy, zz);
#endif
  generic::AdvanceRun(run, fn, zx, zy, zz);
}

const char* ContactKernelIsa() {
#if defined(__x86_64__)
  return UseAvx2Kernels() ? "avx2" : "sse2";
#else
  return "generic";
#endif
}

}  // namespace graspsim::contact_kernel
