// CollidingLanes for any CPU: the same code compiled for the target's baseline (SSE2 on x86-64: two 4-lane
// instructions per operation).
#include "motion/sphere_kernel.h"

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

namespace graspsim::motion::kernel::generic {

#include "motion/sphere_kernel_impl.inc"

uint32_t CollidingLanes(const Model& model, const float* q, const float* inflate, float* scratch, bool stop_at_first) {
  return CollidingLanesImpl(model, q, inflate, scratch, stop_at_first);
}

}  // namespace graspsim::motion::kernel::generic
