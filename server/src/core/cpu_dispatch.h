// Which build of a SIMD kernel runs: the contact law and the motion checker each compile an AVX2+FMA build beside
// the baseline one and ask here, once, which to call.
#pragma once

namespace graspsim {

// True on x86-64 CPUs with AVX2 and FMA, unless GRASPSIM_KERNEL=generic forces the baseline build (for tests that
// compare the two). Decided at the first call.
bool UseAvx2Kernels();

}  // namespace graspsim
