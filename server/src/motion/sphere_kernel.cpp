#include "motion/sphere_kernel.h"

#include "core/cpu_dispatch.h"

namespace graspsim::motion::kernel {

uint32_t CollidingLanes(const Model& model, const float* q, const float* inflate, float* scratch, StopLanes stop) {
#if defined(__x86_64__)
  if (UseAvx2Kernels()) return avx2::CollidingLanes(model, q, inflate, scratch, stop);
#endif
  return generic::CollidingLanes(model, q, inflate, scratch, stop);
}

uint32_t ClearanceLanes(const Model& model, const float* q, const float* cap, float* scratch, float* clearance,
                        StopLanes stop) {
#if defined(__x86_64__)
  if (UseAvx2Kernels()) return avx2::ClearanceLanes(model, q, cap, scratch, clearance, stop);
#endif
  return generic::ClearanceLanes(model, q, cap, scratch, clearance, stop);
}

const char* KernelIsa() {
#if defined(__x86_64__)
  if (UseAvx2Kernels()) return "avx2";
  return "sse2";
#else
  return "generic";
#endif
}

}  // namespace graspsim::motion::kernel
