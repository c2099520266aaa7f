// Accuracy of the engine against two analytic answers of tests/cpp/physics/simulation_test.cpp, at any time
// step and integrator: for the benchmark's runtime-versus-error table (tests/bench/physics.py).
#pragma once

#include <string>

#include "world/simulation_params.h"

namespace graspsim::stress {

struct Accuracy {
  double rel_error = 0;   // |measured / analytic − 1|; the worst over the cases of the test
  double peak_rel_error = 0;  // settle only: the first overshoot against the damped oscillator's
  double worst_speed = 0;     // stribeck only: the imposed speed (m/s) with the largest error
  double seconds = 0;     // wall time of the simulation: reported, never asserted
  long steps = 0;         // steps taken
  std::string error;      // a divergence report or a broken precondition (then rel_error is meaningless)
};

// A 0.5 kg sphere (r = 3 cm, one contact point) released at rest touching the table settles for 3 s: the final
// depth vs m g / (k/2) (k = 1e4 N/m), and the deepest point of the transient vs the step response of the
// spring-damper, d_s (1 + exp(−ζπ/√(1−ζ²))) with ζ = (c/2) / (2 √(k/2 · m)) = 0.1.
Accuracy SettleAccuracy(Integrator integrator, double time_step);

// A sphere dragged over the table at imposed speeds 1e-4 … 1 m/s: friction vs the LuGre steady state
// g(v) + c_t v (μs 0.6, μd 0.4, v_s 1 cm/s, c_t 0.05 N s/m, normal force 9.81 N).
Accuracy StribeckAccuracy(Integrator integrator, double time_step);

}  // namespace graspsim::stress
