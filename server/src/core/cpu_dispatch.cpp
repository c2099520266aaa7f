#include "core/cpu_dispatch.h"

#include <cstdlib>
#include <cstring>

namespace graspsim {

bool UseAvx2Kernels() {
#if defined(__x86_64__)
  static const bool use = [] {
    const char* forced = std::getenv("GRASPSIM_KERNEL");
    if (forced && std::strcmp(forced, "generic") == 0) return false;
    __builtin_cpu_init();
    return __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma");
  }();
  return use;
#else
  return false;
#endif
}

}  // namespace graspsim
