// The contact kernel (contact_kernel.h) for CPUs with AVX2 and FMA, four contacts per instruction; compiled with
// -mavx2 -mfma (physics/CMakeLists.txt) and only called when the CPU has both (contact_kernel.cpp).
#include "physics/contact_kernel.h"

#include <immintrin.h>

#include <cstdint>

namespace graspsim::contact_kernel::avx2 {

constexpr int kWidth = 4;
#include "physics/contact_kernel_impl.inc"

void EvaluateRun(const ContactRun& run, bool linearize, double* fx, double* fy, double* fz, double* fn,
                 RunSums* sums) {
  EvaluateRunImpl(run, linearize, fx, fy, fz, fn, sums);
}

void AdvanceRun(const ContactRun& run, const double* fn, double* zx, double* zy, double* zz) {
  AdvanceRunImpl(run, fn, zx, zy, zz);
}

}  // namespace graspsim::contact_kernel::avx2
