// graspsim_physics_bench: the in-process accuracy figures of `tests/bench/run physics` as one JSON object:
// {"settle": [...], "stribeck": [...]}, one entry per time step × integrator with the relative error against the
// analytic answer (settle: also of the transient's peak) and the wall time (stress/accuracy.h). Progress: stderr.
#include <cstdio>
#include <iostream>
#include <sstream>
#include <vector>

#include "stress/accuracy.h"
#include "stress/sweep.h"

int main() {
  using namespace graspsim;
  using namespace graspsim::stress;
  const std::vector<double> steps = {1e-4, 3e-4, 1e-3, 3e-3, 1e-2};
  const std::vector<Integrator> integrators = {Integrator::kSemiImplicitEuler, Integrator::kLinearlyImplicitEuler,
                                               Integrator::kVelocityVerlet};
  std::ostringstream out;
  out.precision(6);
  for (const char* test : {"settle", "stribeck"}) {
    out << (out.tellp() > 0 ? "," : "{") << "\"" << test << "\":[";
    bool first = true;
    for (Integrator integrator : integrators) {
      for (double dt : steps) {
        const Accuracy a = std::string(test) == "settle" ? SettleAccuracy(integrator, dt) : StribeckAccuracy(integrator, dt);
        std::cerr << test << " " << Name(integrator) << " dt=" << dt << ": " << a.rel_error << " (peak "
                  << a.peak_rel_error << ") in " << a.seconds
                  << " s " << a.error << "\n";
        std::string error;
        for (char ch : a.error) error += (ch == '"' || ch == '\\') ? '\'' : ch;
        out << (first ? "" : ",") << "{\"integrator\":\"" << Name(integrator) << "\",\"dt\":" << dt
            << ",\"rel_error\":" << a.rel_error;
        if (std::string(test) == "settle") out << ",\"peak_rel_error\":" << a.peak_rel_error;
        if (std::string(test) == "stribeck") out << ",\"worst_speed\":" << a.worst_speed;
        out << ",\"seconds\":" << a.seconds << ",\"steps\":" << a.steps
            << ",\"error\":\"" << error << "\"}";
        first = false;
      }
    }
    out << "]";
  }
  std::cout << out.str() << "}" << std::endl;
  return 0;
}
