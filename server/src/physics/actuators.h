// Actuators on joints: a DC motor with gearbox, driven by voltage, velocity or position (PAPERS.md part A), and
// the Schunk PG70 finger drive (velocity control with a maximum current, i.e. a force limit).
//
// Motor: V = R i + L di/dt + k_e ω_m,  τ_m = k_t i,  ω_m = ratio · q̇,  joint force/torque τ = ratio · η · τ_m.
// With L = 0 the current follows the voltage at once: i = (V - k_e ω_m) / R. The current is clamped to
// ±current_limit, the voltage to ±voltage_limit. `ratio` is motor rad per joint unit (rad or m).
#pragma once

#include "world/simulation_params.h"

namespace graspsim {

struct ActuatorOutput {
  double joint_force = 0;        // N m or N on the joint
  double current = 0;            // A
  double voltage = 0;            // V
  // The force's derivatives over this step, for the implicit solve: the back-EMF and the velocity loop damp a
  // geared motor far too stiffly for an explicit step (the PG70 finger: ~3 kN s/m on 0.1 kg).
  double damping = 0;            // ∂force/∂q̇, N s/m or N m s/rad (≤ 0)
  double stiffness = 0;          // ∂force/∂q, N/m or N m/rad (≤ 0; position mode)
};

// One control step: the motor's output for the joint's position q and velocity q̇ over dt (state advanced).
ActuatorOutput StepDcMotor(const DcMotorParams& params, const ActuatorCommand& command, double q, double q_dot,
                           double dt, DcMotorState* state);

// The Schunk PG70 finger drive: velocity control of the finger joint (m/s) with a maximum motor current; its
// parameters reproduce the datasheet's 200 N gripping force at the rated current and 82 mm/s top speed.
DcMotorParams Pg70DriveParams();

}  // namespace graspsim
