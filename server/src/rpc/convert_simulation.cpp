// Simulation parameters and actuator commands: messages ↔ engine types, validated at the boundary.
#include "core/error.h"
#include "core/validate.h"
#include "rpc/convert.h"

namespace graspsim::rpc {
namespace {

// A proto3 double left at 0 keeps the default; a given one must be positive (or non-negative).
double PositiveOr(const std::string& field, double value, double fallback) {
  if (value == 0) return fallback;
  CheckPositive(field, value);
  return value;
}

}  // namespace

SimulationParams SimulationParamsFromProto(const std::string& field, const v1::SimulationParams& p,
                                           const SimulationParams& defaults) {
  SimulationParams out = defaults;
  out.time_step = PositiveOr(field + ".time_step", p.time_step(), defaults.time_step);
  if (p.substeps() != 0) {
    if (p.substeps() > 1000) ThrowInvalidArgument(field + ".substeps: " + std::to_string(p.substeps()) + " is above 1000");
    out.substeps = static_cast<int>(p.substeps());
  }
  switch (p.integrator()) {
    case v1::INTEGRATOR_SEMI_IMPLICIT_EULER: out.integrator = Integrator::kSemiImplicitEuler; break;
    case v1::INTEGRATOR_LINEARLY_IMPLICIT_EULER: out.integrator = Integrator::kLinearlyImplicitEuler; break;
    case v1::INTEGRATOR_VELOCITY_VERLET: out.integrator = Integrator::kVelocityVerlet; break;
    case v1::INTEGRATOR_RUNGE_KUTTA_4: out.integrator = Integrator::kRungeKutta4; break;
    case v1::INTEGRATOR_UNSPECIFIED: break;
    default: ThrowInvalidArgument(field + ".integrator: " + std::to_string(p.integrator()) + " is not an integrator");
  }
  switch (p.engine()) {
    case v1::PHYSICS_ENGINE_UNSPECIFIED: break;
    case v1::PHYSICS_ENGINE_GRASPSIM: out.engine = PhysicsEngineKind::kGraspsim; break;
    case v1::PHYSICS_ENGINE_MUJOCO: out.engine = PhysicsEngineKind::kMujoco; break;
    case v1::PHYSICS_ENGINE_BULLET: out.engine = PhysicsEngineKind::kBullet; break;
    default: ThrowInvalidArgument(field + ".engine: " + std::to_string(p.engine()) + " is not an engine");
  }
  if (p.has_gravity()) {
    out.gravity = FromProto(p.gravity());
    CheckFinite(field + ".gravity", out.gravity);
  }
  const auto& c = p.contact();
  out.contact.stiffness = PositiveOr(field + ".contact.stiffness", c.stiffness(), defaults.contact.stiffness);
  out.contact.damping = PositiveOr(field + ".contact.damping", c.damping(), defaults.contact.damping);
  out.contact.bristle_stiffness =
      PositiveOr(field + ".contact.bristle_stiffness", c.bristle_stiffness(), defaults.contact.bristle_stiffness);
  out.contact.bristle_damping =
      PositiveOr(field + ".contact.bristle_damping", c.bristle_damping(), defaults.contact.bristle_damping);
  out.contact.viscous_friction =
      PositiveOr(field + ".contact.viscous_friction", c.viscous_friction(), defaults.contact.viscous_friction);
  out.contact.stribeck_velocity =
      PositiveOr(field + ".contact.stribeck_velocity", c.stribeck_velocity(), defaults.contact.stribeck_velocity);
  out.sample_spacing = PositiveOr(field + ".sample_spacing", p.sample_spacing(), defaults.sample_spacing);
  out.sleep_speed = PositiveOr(field + ".sleep_speed", p.sleep_speed(), defaults.sleep_speed);
  out.sleep_time = PositiveOr(field + ".sleep_time", p.sleep_time(), defaults.sleep_time);
  return out;
}

void ToProto(const SimulationParams& params, v1::SimulationParams* out) {
  out->set_time_step(params.time_step);
  out->set_substeps(params.substeps);
  switch (params.integrator) {
    case Integrator::kSemiImplicitEuler: out->set_integrator(v1::INTEGRATOR_SEMI_IMPLICIT_EULER); break;
    case Integrator::kLinearlyImplicitEuler: out->set_integrator(v1::INTEGRATOR_LINEARLY_IMPLICIT_EULER); break;
    case Integrator::kVelocityVerlet: out->set_integrator(v1::INTEGRATOR_VELOCITY_VERLET); break;
    case Integrator::kRungeKutta4: out->set_integrator(v1::INTEGRATOR_RUNGE_KUTTA_4); break;
  }
  switch (params.engine) {
    case PhysicsEngineKind::kGraspsim: out->set_engine(v1::PHYSICS_ENGINE_GRASPSIM); break;
    case PhysicsEngineKind::kMujoco: out->set_engine(v1::PHYSICS_ENGINE_MUJOCO); break;
    case PhysicsEngineKind::kBullet: out->set_engine(v1::PHYSICS_ENGINE_BULLET); break;
  }
  ToProto(params.gravity, out->mutable_gravity());
  auto* c = out->mutable_contact();
  c->set_stiffness(params.contact.stiffness);
  c->set_damping(params.contact.damping);
  c->set_bristle_stiffness(params.contact.bristle_stiffness);
  c->set_bristle_damping(params.contact.bristle_damping);
  c->set_viscous_friction(params.contact.viscous_friction);
  c->set_stribeck_velocity(params.contact.stribeck_velocity);
  out->set_sample_spacing(params.sample_spacing);
  out->set_sleep_speed(params.sleep_speed);
  out->set_sleep_time(params.sleep_time);
}

DcMotorParams DcMotorFromProto(const std::string& field, const v1::DcMotor& m) {
  DcMotorParams out;
  out.resistance = PositiveOr(field + ".resistance", m.resistance(), out.resistance);
  CheckNonNegative(field + ".inductance", m.inductance());
  out.inductance = m.inductance();
  out.torque_constant = PositiveOr(field + ".torque_constant", m.torque_constant(), out.torque_constant);
  out.ratio = PositiveOr(field + ".ratio", m.ratio(), out.ratio);
  out.efficiency = PositiveOr(field + ".efficiency", m.efficiency(), out.efficiency);
  if (out.efficiency > 1) ThrowInvalidArgument(field + ".efficiency: " + std::to_string(out.efficiency) + " is above 1");
  out.current_limit = PositiveOr(field + ".current_limit", m.current_limit(), out.current_limit);
  out.voltage_limit = PositiveOr(field + ".voltage_limit", m.voltage_limit(), out.voltage_limit);
  return out;
}

ActuatorCommand ActuatorCommandFromProto(const std::string& field, const v1::ActuatorCommand& command) {
  ActuatorCommand out;
  switch (command.mode()) {
    case v1::ACTUATOR_MODE_OFF: out.mode = ActuatorMode::kOff; break;
    case v1::ACTUATOR_MODE_VOLTAGE: out.mode = ActuatorMode::kVoltage; break;
    case v1::ACTUATOR_MODE_VELOCITY: out.mode = ActuatorMode::kVelocity; break;
    case v1::ACTUATOR_MODE_POSITION: out.mode = ActuatorMode::kPosition; break;
    default: ThrowInvalidArgument(field + ".mode: " + std::to_string(command.mode()) + " is not an actuator mode");
  }
  CheckFinite(field + ".value", command.value());
  out.value = command.value();
  CheckNonNegative(field + ".current_limit", command.current_limit());
  out.current_limit = command.current_limit() > 0 ? command.current_limit() : -1;
  return out;
}

}  // namespace graspsim::rpc
