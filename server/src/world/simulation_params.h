// Simulation parameters and actuator settings as plain data: part of a scene's model (parameters) and state
// (actuator commands and motor states). The behaviour lives in server/src/physics.
#pragma once

#include "core/math.h"

namespace graspsim {

// Contact-law parameters (physics/contact_law.h states the law).
struct ContactParams {
  double stiffness = 1e4;          // k, N/m per contact point
  double damping = 10;             // c, N s/m
  double static_friction = 0.6;    // μ_s
  double dynamic_friction = 0.4;   // μ_d
  double bristle_stiffness = 1e4;  // σ0, N/m
  double bristle_damping = 30;     // σ1, N s/m
  double viscous_friction = 0;     // c_t, N s/m
  double stribeck_velocity = 1e-3; // v_s, m/s

  // Without friction coefficients or bristle stiffness a contact keeps no bristle state at all.
  bool HasFriction() const { return bristle_stiffness > 0 && (static_friction > 0 || dynamic_friction > 0); }
};

// A DC motor with gearbox on a joint (physics/actuators.h states the model).
struct DcMotorParams {
  double resistance = 1.0;       // R, Ω
  double inductance = 0;         // L, H (0 = neglected)
  double torque_constant = 0.05; // k_t = k_e, N m/A (= V s/rad)
  double ratio = 100;            // motor rad per joint rad (or per joint m for a prismatic joint)
  double efficiency = 1.0;       // η, 0..1
  double current_limit = 5;      // A
  double voltage_limit = 24;     // V
  // Controllers: velocity mode is PI on joint velocity (output volts), position mode is P on position giving a
  // velocity set-point (capped at max_velocity) for the velocity loop.
  double velocity_gain = 50;     // V per (joint unit/s)
  double velocity_integral_gain = 500;  // V per joint unit
  double position_gain = 20;     // 1/s
  double max_velocity = 1;       // joint unit/s
};

enum class ActuatorMode { kOff, kVoltage, kVelocity, kPosition };

struct ActuatorCommand {
  ActuatorMode mode = ActuatorMode::kOff;
  double value = 0;              // V, joint unit/s or joint unit, by mode
  double current_limit = -1;     // A; < 0 = the motor's own limit (the PG70's force control sets this)
};

struct DcMotorState {
  double current = 0;            // A
  double velocity_error_integral = 0;  // joint units
};

enum class Integrator { kSemiImplicitEuler, kLinearlyImplicitEuler, kVelocityVerlet, kRungeKutta4 };

// The physics engine a scene runs on (physics/engine.h): graspsim's own, MuJoCo or Bullet.
enum class PhysicsEngineKind { kGraspsim, kMujoco, kBullet };

struct SimulationParams {
  double time_step = 1e-3;                      // s, one step
  int substeps = 1;                             // integration steps per step (h = time_step / substeps)
  Integrator integrator = Integrator::kLinearlyImplicitEuler;
  PhysicsEngineKind engine = PhysicsEngineKind::kGraspsim;
  Vec3 gravity = Vec3(0, 0, -9.81);             // m/s²
  ContactParams contact;                        // defaults for materials that leave a parameter at 0
  double sample_spacing = 0.005;                // m, between surface samples of primitives
  double sleep_speed = 1e-3;                    // m/s and rad/s: slower free bodies are at rest
  double sleep_time = 0.5;                      // s at rest before a body sleeps
  double divergence_speed = 1e3;                // m/s or rad/s: faster means the integration has diverged
};

// One joint's drive as the state holds it: settings, motor state, and the last output.
struct JointActuator {
  DcMotorParams motor;
  ActuatorCommand command;
  DcMotorState state;
  double joint_force = 0;  // N m or N, last step
  double voltage = 0;      // V, last step
};

}  // namespace graspsim
