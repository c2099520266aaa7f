// Numerical-stability stress runs of the physics engine (issue "Physics engine", Must show: stability).
//
// One RunSpec is one parameter point of one scenario; RunOne builds the scene, steps it one step at a time for
// a capped simulated time and classifies the run:
//   stable    no divergence reported, every state finite, and physically sane once the contact onset is past
//             (sweep.cpp): the total energy (kinetic + gravity + contact springs + bristle springs, which physics
//             can only dissipate) never climbing, in the second half of the run, above its lowest value so far
//             by more than the bodies' settling oscillation energy Σ ½ W d_s (+ 1 % of a slider's launch
//             energy), and no contact deeper than 4 × its static answer in the last tenth.
//   unstable  reason "diverged": Simulation::Step threw, and the report is checked (FAILED_PRECONDITION, the
//             message names a body or joint, the step and the quantity, the state is finite and untouched); or
//             "energy" / "penetration": finite but outside the bounds above.
// A contract breach (NaN in a returned state, another error code, a message without body, step or quantity,
// a touched state) is recorded in `contract`: an engine bug, whatever the verdict.
#pragma once

#include <string>
#include <vector>

#include "world/model.h"
#include "world/simulation_params.h"

namespace graspsim::stress {

enum class Scenario {
  kTipOnTable,   // a fingertip: sphere r = 1 cm of `mass`, resting on a static table
  kTipOnObject,  // the fingertip resting on a 3 kg, 10 cm box that rests on the table (mass ratio mass / 3 kg)
  kSlide,        // a 5 cm box of `mass` launched over the table at 0.2 m/s: friction stops it (Coulomb: in 51 ms)
};

// The simulated time a slide run gets at least (RunSpec::min_duration), whatever the time step.
inline constexpr double kSlideMinDuration = 0.1;

struct RunSpec {
  std::string grid = "main";  // which sub-sweep the point belongs to (for the tables)
  Scenario scenario = Scenario::kTipOnTable;
  Integrator integrator = Integrator::kLinearlyImplicitEuler;
  double time_step = 1e-3;    // s
  double mass = 0.05;         // kg: the fingertip or the slider
  ContactParams contact;      // scene defaults; every body leaves its material at 0, so pairs get k/2, c/2
  double duration = 0.5;      // s simulated, unless max_steps comes first
  int max_steps = 2000;       // caps the cost of small time steps …
  double min_duration = 0;    // … but at least this many s (the slide needs ~0.1 s to stop and be judged at rest)
  bool trace = false;         // print every step (energy, depth, the bodies' motion) to stderr
};

struct RunResult {
  bool stable = false;
  std::string reason;        // "" (stable), "diverged", "penetration", "energy"
  std::string contract;      // "" or what the engine did wrong (see above)
  std::string error;         // the divergence message, if any
  int steps_planned = 0, steps_run = 0;
  double energy_growth = 0;    // worst climb of the energy above its lowest so far / its allowance, second
                               // half of the run (judged: ≤ 1; sweep.cpp)
  double end_depth_ratio = 0;  // worst contact depth / its static answer, last tenth of the run (judged: ≤ 4)
  double onset_depth_ratio = 0;  // worst contact depth / its static answer over the whole run (reported only)
  double onset_energy_gain = 0;  // worst (E − E0) / Σ ½ W d_s over the whole run (reported only)
  double friction_ratio = 0;   // worst |F_t| / (μ_s F_n) of the engine's contact forces (reported only)
  double slide = 0;            // m the slider (tip) travelled along x
  double slide_ratio = 0;      // kSlide: slide / the Coulomb answer v0² / (2 μ_d g) (reported only)
  double seconds = 0;          // wall time of the run: reported, never asserted
};

RunResult RunOne(const RunSpec& spec);

// One JSON object (one line) with the spec and the result.
std::string ToJson(const RunSpec& spec, const RunResult& result);

// The sweep grids (sweep.cpp states them). Reduced: the main grid at 2 masses and 4 time steps, for benchmarks.
std::vector<RunSpec> FullSweep();
std::vector<RunSpec> ReducedSweep();

// Scene parts shared with accuracy.h: free bodies with uniform-density inertia, and the static table (a
// 10 × 10 × 1 m slab, top at z = 0, as a mesh: sampled at its 8 far corners only, so every contact is a sample
// of a body resting on it and the analytic answers can count them).
BodySpec SphereBody(const std::string& id, double radius, double mass);
BodySpec CubeBody(const std::string& id, double edge, double mass);
BodySpec TableBody();

const char* Name(Scenario scenario);
const char* Name(Integrator integrator);

}  // namespace graspsim::stress
