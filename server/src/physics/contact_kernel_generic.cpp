// The contact kernel (contact_kernel.h) for any CPU: the same code compiled for the target's baseline (SSE2 on
// x86-64), two contacts per instruction.
#include "physics/contact_kernel.h"

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#include <cstdint>

namespace graspsim::contact_kernel::generic {

constexpr int kWidth = 2;
#include "physics/contact_kernel_impl.inc"

void EvaluateRun(const ContactRun& run, bool linearize, double* fx, double* fy, double* fz, double* fn,
                 RunSums* sums) {
  EvaluateRunImpl(run, linearize, fx, fy, fz, fn, sums);
}

void AdvanceRun(const ContactRun& run, const double* fn, double* zx, double* zy, double* zz) {
  AdvanceRunImpl(run, fn, zx, zy, zz);
}

}  // namespace graspsim::contact_kernel::generic
