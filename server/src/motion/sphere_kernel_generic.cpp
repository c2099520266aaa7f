// CollidingLanes and ClearanceLanes for any CPU: the same code compiled for the target's baseline (SSE2 on x86-64), 4 lanes per
// instruction, run on lanes 0-3 and then 4-7.
#include "motion/sphere_kernel.h"

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

namespace graspsim::motion::kernel::generic {

constexpr int kWidth = 4;
#include "motion/sphere_kernel_impl.inc"

uint32_t CollidingLanes(const Model& model, const float* q, const float* inflate, float* scratch, StopLanes stop) {
  const uint32_t low = CollidingLanesImpl(model, q, inflate, scratch, stop.mask & 0xfu);
  if (low & stop.mask) return low;
  return low | (CollidingLanesImpl(model, q + kWidth, inflate + kWidth, scratch + kWidth, stop.mask >> kWidth) << kWidth);
}

uint32_t ClearanceLanes(const Model& model, const float* q, const float* cap, float* scratch, float* clearance,
                        StopLanes stop) {
  const uint32_t low = ClearanceLanesImpl(model, q, cap, scratch, clearance, stop.mask & 0xfu);
  if (low & stop.mask) return low;
  return low | (ClearanceLanesImpl(model, q + kWidth, cap + kWidth, scratch + kWidth, clearance + kWidth,
                                   stop.mask >> kWidth)
                << kWidth);
}

}  // namespace graspsim::motion::kernel::generic
