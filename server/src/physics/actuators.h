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
  // The current limit as a constraint of the step. free_*: the force the controller asks for and its
  // derivatives as if there were no limit; force_limit: the largest |force| the limit allows; limited: the
  // limit holds this step (joint_force = ±force_limit, damping = stiffness = 0).
  double free_force = 0, free_damping = 0, free_stiffness = 0;
  double force_limit = 0;
  bool limited = false;
};

// How a step decides whether the current limit holds. kAuto: at the joint's velocity at the start of the step.
// The others: as the caller decided, at the step's new velocity (the simulation's implicit solve treats the
// limit as an active constraint, force = clamp(free force at the new velocity): a drive that saturates within a
// large step is then not stepped explicitly, which made position loops chatter).
enum class CurrentLimitMode { kAuto, kFree, kAtPositiveLimit, kAtNegativeLimit };

// One control step: the motor's output for the joint's position q and velocity q̇ over dt (state advanced).
ActuatorOutput StepDcMotor(const DcMotorParams& params, const ActuatorCommand& command, double q, double q_dot,
                           double dt, DcMotorState* state, CurrentLimitMode mode = CurrentLimitMode::kAuto);

// The Schunk PG70 finger drive: velocity control of the finger joint (m/s) with a maximum motor current; its
// parameters reproduce the datasheet's 200 N gripping force at the rated current and 82 mm/s top speed.
DcMotorParams Pg70DriveParams();

}  // namespace graspsim
