// Simulation's drive stage (physics/simulation.h): each driven joint's motor, with its current limit decided
// at the step's new velocity (LimitCurrents) and the force the step applied recorded.
#include <algorithm>
#include <cmath>

#include "physics/simulation.h"

namespace graspsim {
namespace {

// The drive's free (unlimited) force at the step's new velocity v⁺, by the linearisation the solve used:
// f + D (v⁺ − v) + K h v⁺.
double FreeForceAt(const ActuatorOutput& out, double v, double v_next, double h) {
  return out.free_force + out.free_damping * (v_next - v) + out.free_stiffness * h * v_next;
}

}  // namespace

void Simulation::ActuatorForces(SceneState* state, double h, Forces* forces) {
  // Each motor's force on its joint; the motors' electrical state advances once per sub-step. The state before
  // the step is kept: LimitCurrents may step a motor again with the current limit decided otherwise.
  drives_.clear();
  for (auto& [joint, actuator] : state->actuators) {
    const int offset = multibody_.JointOffset(joint);
    if (offset < 0) continue;
    Drive& drive = drives_.emplace_back(Drive{joint, offset, actuator.state, {}});
    drive.output = StepDcMotor(actuator.motor, actuator.command, state->joint_positions[joint],
                               state->joint_velocities[joint], h, &actuator.state);
    actuator.joint_force = drive.output.joint_force;
    actuator.voltage = drive.output.voltage;
    forces->actuators[offset] += drive.output.joint_force;
    forces->actuator_damping[offset] += drive.output.damping;
    forces->actuator_stiffness[offset] += drive.output.stiffness;
  }
  forces->tau += forces->actuators;
}

bool Simulation::LimitCurrents(const Eigen::VectorXd& v, const Eigen::VectorXd& v_next, double h, SceneState* state,
                               Forces* forces) {
  // The current limit is decided at the step's new velocity, not its start (FreeForceAt). A drive whose decision changes is
  // stepped again from its state before the step with the other law, and its force and derivatives in *forces
  // are replaced. Returns whether any changed (the caller solves again).
  bool changed = false;
  for (Drive& drive : drives_) {
    const ActuatorOutput& out = drive.output;
    const int o = drive.offset;
    const double free_force = FreeForceAt(out, v[o], v_next[o], h);
    // force = clamp(free force) is a monotone (falling) law of the new velocity, so the step's solution is
    // unique; it is found like an active set: a drive at a limit whose free force at the new velocity is not
    // beyond that limit goes free, a free drive whose free force is beyond a limit goes to it. Never from one
    // limit straight to the other: the solution then lies between them (a stiff loop's linear range can be
    // narrower than one step's velocity change at the limit force).
    CurrentLimitMode mode;
    if (out.limited) {
      const bool beyond = out.joint_force > 0 ? free_force >= out.force_limit : free_force <= -out.force_limit;
      if (beyond) continue;
      mode = CurrentLimitMode::kFree;
    } else {
      if (std::abs(free_force) <= out.force_limit) continue;
      mode = free_force > 0 ? CurrentLimitMode::kAtPositiveLimit : CurrentLimitMode::kAtNegativeLimit;
    }
    JointActuator& actuator = state->actuators.at(drive.joint);
    actuator.state = drive.state_before;
    const ActuatorOutput again =
        StepDcMotor(actuator.motor, actuator.command, state->joint_positions[drive.joint], v[o], h, &actuator.state, mode);
    actuator.joint_force = again.joint_force;
    actuator.voltage = again.voltage;
    forces->actuators[o] += again.joint_force - out.joint_force;
    forces->tau[o] += again.joint_force - out.joint_force;
    forces->actuator_damping[o] += again.damping - out.damping;
    forces->actuator_stiffness[o] += again.stiffness - out.stiffness;
    drive.output = again;
    changed = true;
  }
  return changed;
}

void Simulation::RecordDriveOutputs(const Eigen::VectorXd& v, const Eigen::VectorXd& v_next, double h,
                                    SceneState* state) const {
  // What a drive reports is the force the solve applied: for a drive off its limit the linearised force at the
  // new velocity (at the start velocity it may lie beyond the limit when the decision was made at the new one),
  // and the current that gives it; it is within the limit but for a decision the passes left unsettled.
  for (const Drive& drive : drives_) {
    const ActuatorOutput& out = drive.output;
    if (out.limited || out.force_limit <= 0) continue;
    const int o = drive.offset;
    const double force = std::clamp(FreeForceAt(out, v[o], v_next[o], h), -out.force_limit, out.force_limit);
    JointActuator& actuator = state->actuators.at(drive.joint);
    const DcMotorParams& motor = actuator.motor;
    actuator.state.current = force / (motor.ratio * motor.efficiency * motor.torque_constant);  // > 0: force_limit > 0
    actuator.joint_force = force;
  }
}

}  // namespace graspsim
