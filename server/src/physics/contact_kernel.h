// The contact law (physics/contact_law.h) over a run of contacts — one body pair, one law — in SIMD lanes, with
// the sums a pair's generalised force and 6 × 6 stiffness block need, and the bristle update. A tactile pad's
// elements are such a run (the work cycle's hot path: ~156 of them every step); the arithmetic is
// contact_law.cpp's, with sums reassociated across lanes. Plain data in, one array per coordinate; compiled twice
// (AVX2 + FMA, and the baseline: contact_kernel_avx2.cpp / contact_kernel_generic.cpp from
// contact_kernel_impl.inc) and chosen once at run time (contact_kernel.cpp), so no inline function may be shared
// between the two builds: the kernel reads ContactParams' fields, never its member functions.
#pragma once

#include <cstddef>

#include "world/simulation_params.h"

namespace graspsim::contact_kernel {

// A run's contacts, `count` of each array: points (world, m), normals (out of body b), depths (m), bristles at
// the step's start (world, m).
struct ContactRun {
  size_t count = 0;
  const double *px = nullptr, *py = nullptr, *pz = nullptr;
  const double *nx = nullptr, *ny = nullptr, *nz = nullptr;
  const double* depth = nullptr;
  const double *zx = nullptr, *zy = nullptr, *zz = nullptr;
  // The pair's relative twist [ω; v] (a's minus b's, world, about the origin): v_rel(p) = v + ω × p.
  double twist[6] = {0, 0, 0, 0, 0, 0};
  ContactParams law;
  bool friction = false;  // law.HasFriction(), decided by the caller
  double h = 0;           // the sub-step, s
  // AdvanceRun: the step was linearly implicit, so the bristles advance with the normal force at its end
  // (contact_law.h's StepEndNormalForce) rather than fn.
  bool step_end_normal = false;
};

// What the pair needs of a run, summed over its contacts (f the force on a, p the point):
struct RunSums {
  double force[3], moment[3];  // Σ f, Σ p × f
  // The linearisation h D + h² K of each contact, in ContactForce's scalar form, as Σ Eᵀ (·) E pieces:
  // Σ a, Σ a p, Σ a p pᵀ (xx xy xz yy yz zz) of the isotropic coefficient a = h d_iso + h² k_iso;
  double isotropic[10];
  // the same of the normal coefficient b = h d_normal + h² k_normal over contacts whose normal is the run's first;
  double along[10];
  // Σ b w wᵀ, w = [p × n; n], over the others (row-major 6 × 6);
  double normal_block[36];
  // Σ w_s (β_s w_s + β_n w_n)ᵀ, w_s = [p × ŝ; ŝ], β_s = h² k_slip, β_n = h d_slip_normal + h² k_slip_normal;
  double slip_block[36];
  // Σ [p × k; k], k = K v_rel: the pair's h² K v before h² and the Jacobian.
  double stiffness_twist[6];
};

// The law at every contact of the run: the force on a into fx, fy, fz and |F_n| into fn (each `count` long), and
// the sums (the linearisation's only when `linearize`).
void EvaluateRun(const ContactRun& run, bool linearize, double* fx, double* fy, double* fz, double* fn,
                 RunSums* sums);

// AdvanceBristle at every contact of the run (run.twist: the step's new relative twist; fn the normal forces of
// EvaluateRun, or with run.step_end_normal StepEndNormalForce of them and the depths), into zx, zy, zz.
// Frictionless runs keep no bristles: not to be called for them.
void AdvanceRun(const ContactRun& run, const double* fn, double* zx, double* zy, double* zz);

// "avx2" or "sse2" (x86-64), "generic" elsewhere: the build in use.
const char* ContactKernelIsa();

// The two builds the functions above dispatch to (contact_kernel_{generic,avx2}.cpp); called directly only by
// tests that compare them. The AVX2 one needs a CPU with AVX2 and FMA.
namespace generic {
void EvaluateRun(const ContactRun& run, bool linearize, double* fx, double* fy, double* fz, double* fn,
                 RunSums* sums);
void AdvanceRun(const ContactRun& run, const double* fn, double* zx, double* zy, double* zz);
}  // namespace generic
#if defined(__x86_64__)
namespace avx2 {
void EvaluateRun(const ContactRun& run, bool linearize, double* fx, double* fy, double* fz, double* fn,
                 RunSums* sums);
void AdvanceRun(const ContactRun& run, const double* fn, double* zx, double* zy, double* zz);
}  // namespace avx2
#endif

}  // namespace graspsim::contact_kernel
