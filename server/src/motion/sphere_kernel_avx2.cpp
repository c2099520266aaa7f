// CollidingLanes and ClearanceLanes for CPUs with AVX2 and FMA (8 float lanes per instruction); compiled with -mavx2 -mfma
// (motion/CMakeLists.txt) and only called when the CPU has both (sphere_kernel.cpp).
#include "motion/sphere_kernel.h"

#include <immintrin.h>

namespace graspsim::motion::kernel::avx2 {

constexpr int kWidth = 8;
#include "motion/sphere_kernel_impl.inc"

uint32_t CollidingLanes(const Model& model, const float* q, const float* inflate, float* scratch, StopLanes stop) {
  return CollidingLanesImpl(model, q, inflate, scratch, stop.mask);
}

uint32_t ClearanceLanes(const Model& model, const float* q, const float* cap, float* scratch, float* clearance,
                        StopLanes stop) {
  return ClearanceLanesImpl(model, q, cap, scratch, clearance, stop.mask);
}

}  // namespace graspsim::motion::kernel::avx2
