// Numerical-stability stress runs of the physics engine (issue "Physics engine", Must show: stability).
//
// One RunSpec is one parameter point of one scenario; RunOne builds the scene, steps it one step at a time for
// a capped simulated time and classifies the run:
//   stable    no divergence reported, every state finite, and physically sane: no contact deeper than
//             kDepthFactor × its static answer, and the total energy (kinetic + gravity + contact springs +
//             bristle springs, which physics can only dissipate) never above its start by more than the
//             settling oscillation's own energy (see sweep.cpp for why these bounds).
//   unstable  "diverged": Simulation::Step threw; the report is checked (FAILED_PRECONDITION, the message names
//             a body or joint, the step and the quantity, the state is finite and untouched), or "insane":
//             finite but outside the bounds above.
// A contract breach (NaN in a returned state, another error code, a message without body, step or quantity,
// a touched state) is recorded in `contract`; it is an engine bug, whatever the verdict.
#pragma once

#include <string>
#include <vector>

#include "world/model.h"
#include "world/simulation_params.h"

namespace graspsim::stress {

enum class Scenario {
  kTipOnTable,   // a fingertip: sphere r = 1 cm of `mass`, resting on a static table
  kTipOnObject,  // the fingertip resting on a 3 kg, 10 cm box that rests on the table (mass ratio mass / 3 kg)
  kSlide,        // a 5 cm box of `mass` launched over the table at 0.2 m/s: friction stops it
};

struct RunSpec {
  std::string grid = "main";  // which sub-sweep the point belongs to (for the tables)
  Scenario scenario = Scenario::kTipOnTable;
  Integrator integrator = Integrator::kLinearlyImplicitEuler;
  double time_step = 1e-3;    // s
  double mass = 0.05;         // kg: the fingertip or the slider
  ContactParams contact;      // scene defaults; every body leaves its material at 0, so pairs get k/2, c/2
  double duration = 0.5;      // s simulated, unless max_steps comes first
  int max_steps = 2000;       // caps the cost of small time steps
};

struct RunResult {
  bool stable = false;
  std::string reason;        // "" (stable), "diverged", "penetration", "energy"
  std::string contract;      // "" or what the engine did wrong (see above)
  std::string error;         // the divergence message, if any
  int steps_planned = 0, steps_run = 0;
  double max_depth_ratio = 0;  // worst contact depth / its static answer
  double energy_gain = 0;      // worst (E(t) − E(0)) / the allowed gain; > 1 is insane
  double slide = 0;            // m the slider travelled (kSlide)
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
