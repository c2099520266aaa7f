// The DC motor drive of actuators.h and the Schunk PG70 finger drive.
//
// One step: the controller of the command's mode gives a terminal voltage; the armature current follows it over
// dt (exactly, with V and ω_m held); the drive's current limit clamps it; the gearbox turns it into the joint
// force. The current limit acts like a servo amplifier's current loop: while it holds, the force is exactly
// ratio · η · k_t · i_max whatever the voltage — the PG70's force control.
#include "physics/actuators.h"

#include <algorithm>
#include <cmath>

namespace graspsim {
namespace {

double Symmetric(double x, double limit) { return std::clamp(x, -limit, limit); }

// The armature current after dt under voltage V with the back-EMF e held. L = 0: the current follows at once,
// i = (V − e)/R. L > 0: L di/dt = V − e − R i is linear with constant input, so
// i(dt) = i_ss + (i0 − i_ss) e^{−R dt/L}, i_ss = (V − e)/R — exact for any dt, unlike an Euler step, which
// would need dt < 2L/R (tens of µs for small motors).
double AdvanceCurrent(const DcMotorParams& p, double current, double voltage, double back_emf, double dt) {
  const double steady = (voltage - back_emf) / p.resistance;
  if (!(p.inductance > 0)) return steady;
  return steady + (current - steady) * std::exp(-p.resistance * dt / p.inductance);
}

}  // namespace

ActuatorOutput StepDcMotor(const DcMotorParams& params, const ActuatorCommand& command, double q, double q_dot,
                           double dt, DcMotorState* state, CurrentLimitMode mode) {
  ActuatorOutput out;
  dt = std::max(dt, 0.0);
  if (command.mode == ActuatorMode::kOff) {
    // Off = power stage disabled: the terminals are open, no current flows (an inductive current dies in the
    // flyback diodes far within a step) and the motor neither drives nor brakes. The velocity loop starts
    // afresh when the drive is switched on again.
    *state = DcMotorState();
    return out;
  }
  // The command may lower the current limit (force control) but not raise it above the drive's own.
  const double current_limit = std::max(
      0.0, command.current_limit >= 0 ? std::min(command.current_limit, params.current_limit) : params.current_limit);
  const double voltage_limit = std::max(0.0, params.voltage_limit);
  const double back_emf = params.torque_constant * params.ratio * q_dot;  // k_e = k_t in SI units

  double voltage = 0;
  double error = 0;  // velocity error of the PI loop, joint units/s
  double integral = 0;
  double dV_dqdot = 0, dV_dq = 0;  // the controller's slopes, for the linearisation
  const bool closed_loop = command.mode == ActuatorMode::kVelocity || command.mode == ActuatorMode::kPosition;
  if (command.mode == ActuatorMode::kVoltage) {
    voltage = Symmetric(command.value, voltage_limit);
  } else if (closed_loop) {
    // Position mode: a P loop gives the velocity set-point, capped at max_velocity so a far target is
    // approached at a bounded speed. Both modes: PI on the joint velocity, volts out.
    const double max_velocity = std::max(0.0, params.max_velocity);
    const double wanted = params.position_gain * (command.value - q);
    const double target = command.mode == ActuatorMode::kVelocity ? command.value : Symmetric(wanted, max_velocity);
    const double dtarget_dq =
        command.mode == ActuatorMode::kPosition && std::abs(wanted) < max_velocity ? -params.position_gain : 0;
    error = target - q_dot;
    integral = state->velocity_error_integral + error * dt;
    // Anti-windup by conditional integration: while the output saturates in the direction the error pushes, the
    // integral holds, so a stalled finger (e.g. closed on an object) does not store a jump for its release.
    const double unsaturated = params.velocity_gain * error + params.velocity_integral_gain * integral;
    bool integrating = true;
    if (std::abs(unsaturated) > voltage_limit && unsaturated * error > 0) {
      integral = state->velocity_error_integral;
      integrating = false;
    }
    const double raw = params.velocity_gain * error + params.velocity_integral_gain * integral;
    voltage = Symmetric(raw, voltage_limit);
    if (std::abs(raw) < voltage_limit) {
      const double gain = params.velocity_gain + (integrating ? params.velocity_integral_gain * dt : 0);
      dV_dqdot = -gain;
      dV_dq = gain * dtarget_dq;
    }
  }

  const double free_current = AdvanceCurrent(params, state->current, voltage, back_emf, dt);
  const double force_per_amp = params.ratio * params.efficiency * params.torque_constant;
  // i = i0 e^{−R dt/L} + (1 − e^{−R dt/L}) (V − k_e ratio q̇)/R: how far the current follows within the step.
  const double follow = params.inductance > 0 ? -std::expm1(-params.resistance * dt / params.inductance) : 1.0;
  out.free_force = force_per_amp * free_current;
  out.free_damping = force_per_amp * follow * (dV_dqdot - params.torque_constant * params.ratio) / params.resistance;
  out.free_stiffness = force_per_amp * follow * dV_dq / params.resistance;
  out.force_limit = force_per_amp * current_limit;
  const bool at_limit_by_caller =
      mode == CurrentLimitMode::kAtPositiveLimit || mode == CurrentLimitMode::kAtNegativeLimit;
  out.limited = at_limit_by_caller || (mode == CurrentLimitMode::kAuto && std::abs(free_current) > current_limit);
  // Limited: ±limit in the direction the controller pushes (at the new velocity when the caller decided). Free
  // by the caller's decision: the free current, which may exceed the limit at the start velocity though not at
  // the new one.
  const double direction = at_limit_by_caller ? (mode == CurrentLimitMode::kAtPositiveLimit ? 1.0 : -1.0)
                                              : free_current;
  const double current = out.limited ? std::copysign(current_limit, direction) : free_current;
  if (out.limited) {
    // The current loop holds |i| at the limit by lowering the terminal voltage to what sustains it
    // (di/dt = 0 at the limit): report that voltage, and hold the integral as for voltage saturation. The
    // force is then constant: no damping, no stiffness.
    voltage = Symmetric(params.resistance * current + back_emf, voltage_limit);
    if (closed_loop && current * error > 0) integral = state->velocity_error_integral;
  } else {
    out.damping = out.free_damping;
    out.stiffness = out.free_stiffness;
  }

  state->current = Symmetric(current, current_limit);
  state->velocity_error_integral = closed_loop ? integral : 0;  // only the PI loop keeps an integral
  out.current = state->current;
  out.voltage = voltage;
  out.joint_force = force_per_amp * current;
  return out;
}

DcMotorParams Pg70DriveParams() {
  // Schunk PG 70 (datasheet): 24 V supply, up to 200 N gripping force, up to 82 mm/s finger speed. The joint is
  // one finger's prismatic joint (m); `ratio` is motor rad per finger metre (spindle lead and gear together).
  //
  // Assumptions (the datasheet gives no motor data):
  // - Rated current 3.5 A: the order of the PG 70's nominal current, not verified here. Only the calibration
  //   below depends on it: at the rated current the drive gives exactly 200 N.
  // - A small 24 V brushless servo motor: k_t = 25 mN m/A, R = 2 Ω (stall current 12 A ≫ rated, so near
  //   stall the force is set by the current limit, not the voltage: the force-control principle).
  // - Spindle and gear efficiency η = 0.8.
  // - Inductance neglected: L/R of such a motor is ~0.1 ms, far below a 1 ms control period.
  // Then ratio = 200 N / (η k_t 3.5 A) ≈ 2857 rad/m (a 2.2 mm effective lead per motor turn), and the no-load
  // speed V/(k_e ratio) = 24 / 71.4 ≈ 0.34 m/s ≥ 82 mm/s, leaving voltage headroom to hold 82 mm/s under load.
  constexpr double kRatedCurrent = 3.5;  // A
  constexpr double kRatedForce = 200;    // N
  DcMotorParams p;
  p.resistance = 2.0;
  p.inductance = 0;
  p.torque_constant = 0.025;
  p.efficiency = 0.8;
  p.ratio = kRatedForce / (p.efficiency * p.torque_constant * kRatedCurrent);
  p.current_limit = kRatedCurrent;
  p.voltage_limit = 24;
  p.max_velocity = 0.082;  // m/s, the datasheet's finger speed: the position loop's speed cap
  // The back-EMF alone damps the finger with B = ratio² η k_t k_e / R ≈ 2 kN s/m; one volt gives
  // b = ratio η k_t / R ≈ 29 N. Kp = 50 V/(m/s) adds ≈ 1.4 kN s/m; Ki = 2000 V/m removes the remaining
  // velocity error with a time constant of (B + b Kp)/(b Ki) ≈ 60 ms. Position gain 20 1/s: a 1 mm error
  // asks for 20 mm/s.
  p.velocity_gain = 50;
  p.velocity_integral_gain = 2000;
  p.position_gain = 20;
  return p;
}

}  // namespace graspsim
