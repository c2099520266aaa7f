#include "physics/simulation.h"

#include <algorithm>
#include <cmath>
#include <utility>

#include <Eigen/LU>

#include "core/error.h"
#include "core/format.h"
#include "core/validate.h"

namespace graspsim {
namespace {

// Extra solves per sub-step to settle which drives are at their current limit (LimitCurrents): a drive settles
// within two (limit → free → the other limit); with several coupled drives the last pass's decision is kept.
constexpr int kCurrentLimitPasses = 4;
// Fixed-point passes of velocity Verlet's second kick (SubStep): each gains a factor h/2 · |∂(M⁻¹b)/∂v|.
constexpr int kVerletBiasPasses = 2;

std::string Vec(const Vec3& v) {
  return "(" + FormatNumber(v.x()) + ", " + FormatNumber(v.y()) + ", " + FormatNumber(v.z()) + ")";
}

}  // namespace

void ValidateSimulationParams(const SimulationParams& p) {
  CheckPositive("params.time_step", p.time_step);
  if (p.time_step > 0.1) ThrowInvalidArgument("params.time_step: " + FormatNumber(p.time_step) + " s is above 0.1 s");
  if (p.substeps < 1 || p.substeps > 1000) {
    ThrowInvalidArgument("params.substeps: " + std::to_string(p.substeps) + " is outside 1..1000");
  }
  CheckFinite("params.gravity", p.gravity);
  CheckNonNegative("params.contact.stiffness", p.contact.stiffness);
  CheckNonNegative("params.contact.damping", p.contact.damping);
  CheckNonNegative("params.contact.bristle_stiffness", p.contact.bristle_stiffness);
  CheckNonNegative("params.contact.bristle_damping", p.contact.bristle_damping);
  CheckNonNegative("params.contact.viscous_friction", p.contact.viscous_friction);
  CheckPositive("params.contact.stribeck_velocity", p.contact.stribeck_velocity);
  CheckPositive("params.sample_spacing", p.sample_spacing);
  if (p.sample_spacing < 1e-4) {
    ThrowInvalidArgument("params.sample_spacing: " + FormatNumber(p.sample_spacing) + " m is below 0.1 mm");
  }
  CheckNonNegative("params.sleep_speed", p.sleep_speed);
  CheckNonNegative("params.sleep_time", p.sleep_time);
  CheckPositive("params.divergence_speed", p.divergence_speed);
}

Simulation::Simulation(std::shared_ptr<const SceneModel> model) : Simulation(SharedSimulationModel(model)) {}

Simulation::Simulation(std::shared_ptr<const SimulationModel> compiled)
    : compiled_(std::move(compiled)),
      model_(compiled_->scene()),
      params_(model_->simulation),
      multibody_(compiled_->multibody()),
      finder_(compiled_->finder()),
      pads_(compiled_->pads()),
      pad_params_(compiled_->pad_params()),
      pad_links_(compiled_->pad_links()),
      body_params_(compiled_->body_params()) {}

void Simulation::PrepareState(SceneState* state) const {
  state->body_velocities.resize(model_->bodies.size());
  state->joint_velocities.resize(model_->joints.size(), 0);
  state->sleeping.resize(model_->bodies.size(), false);
  state->rest_time.resize(model_->bodies.size(), 0);
  state->joint_wrenches.resize(model_->joints.size(), {Vec3::Zero(), Vec3::Zero()});
  state->pad_forces.resize(model_->tactile_arrays.size());
  for (uint32_t pad = 0; pad < model_->tactile_arrays.size(); ++pad) {
    state->pad_forces[pad].resize(pads_.Elements(pad).size(), Vec3::Zero());
  }
}

ContactParams Simulation::PairParams(uint32_t a, uint32_t b) const {
  return CombineContactParams(body_params_[a], body_params_[b]);
}

StepStats Simulation::Step(SceneState* state, int steps, Readings readings) {
  // Step in place, keeping a copy to restore: a diverged run leaves the caller's state as it was. The copy
  // assignment reuses the buffers of the last call. What the call leaves untouched stays out of the copy: the
  // contact list is moved aside and back (only the end of a call that succeeded writes it), and with kSkip the
  // readings are swapped out around the copy (a work cycle steps one step per call, most of them with kSkip).
  const bool record = readings == Readings::kRecord;
  std::vector<SceneState::Contact> contacts = std::move(state->contacts);
  state->contacts.clear();
  std::vector<std::vector<Vec3>> pad_forces;
  std::vector<std::array<Vec3, 2>> joint_wrenches;
  auto swap_readings = [&] {
    if (record) return;
    std::swap(pad_forces, state->pad_forces);
    std::swap(joint_wrenches, state->joint_wrenches);
  };
  swap_readings();
  backup_ = *state;
  swap_readings();
  PrepareState(state);
  const double h = params_.time_step / params_.substeps;
  StepStats stats;
  try {
    for (int s = 0; s < steps; ++s) {
      for (int sub = 0; sub < params_.substeps; ++sub) {
        // What the sensors read (joint wrenches, pad forces) is recorded by the call's last sub-step only: every
        // earlier one would be overwritten unread.
        SubStep(state, h, record && s == steps - 1 && sub == params_.substeps - 1);
        CheckFinite(*state);
      }
      ++state->step;
      state->time += params_.time_step;
    }
  } catch (...) {
    swap_readings();
    *state = backup_;
    swap_readings();
    state->contacts = std::move(contacts);
    throw;
  }
  stats.contacts = contacts_.size();
  state->contacts = std::move(contacts);  // a skipped call's list as it was; a recording one reuses its buffer
  if (record) {
    state->contacts.resize(contacts_.size());
    for (size_t i = 0; i < contacts_.size(); ++i) {
      state->contacts[i] = {contacts_[i].body_a, contacts_[i].body_b, contacts_[i].point, forces_[i]};
    }
  }
  for (size_t i = 0; i < model_->bodies.size(); ++i) {
    stats.awake_bodies += model_->bodies[i].motion == BodyMotion::kFree && !state->sleeping[i];
  }
  return stats;
}

void Simulation::SubStep(SceneState* state, double h, bool record_readings) {
  const Eigen::VectorXd v = multibody_.Velocities(*state);
  Forces& forces = forces_at_start_;
  FindContacts(state);
  ContactForces(*state, v, h, &forces);
  ActuatorForces(state, h, &forces);
  if (params_.integrator == Integrator::kVelocityVerlet) {
    // Kick half a step, drift, evaluate again at the new configuration, kick the other half.
    const Eigen::VectorXd v_half = v + SolveVelocityChange(*state, v, forces, h / 2);
    multibody_.Integrate(v_half, h, state);
    FindContacts(state);
    Forces& second = forces_at_end_;
    ContactForces(*state, v_half, h, &second);
    HoldDrives(forces, &second);
    // The bias forces (Coriolis, centrifugal, gyroscopic) depend on the velocity: taken at v_half, the second
    // kick makes the step first order (issue 21: a double pendulum gained 1.9 % energy in 10 s at 1 ms, a box
    // spun near its middle axis lost 0.5 % of its angular momentum). A fixed point takes them at the step's end
    // velocity (its contraction factor is h/2 · |∂(M⁻¹b)/∂v|, far below 1 wherever a step is stable).
    Eigen::VectorXd v_next = v_half + SolveVelocityChange(*state, v_half, second, h / 2);
    for (int pass = 0; pass < kVerletBiasPasses; ++pass) {
      v_next = v_half + SolveVelocityChange(*state, v_half, second, h / 2, &v_next);
    }
    // The second half kick, at the new configuration.
    if (record_readings) RecordJointWrenches(v_half, v_next, h / 2, state);
    AdvanceBristles(second, v_half, h, state);
    multibody_.SetVelocities(v_next, state);
  } else if (params_.integrator == Integrator::kRungeKutta4) {
    RungeKutta4(v, h, state, record_readings);
  } else {
    // The bristles move with the step's new velocity, the one the implicit solve assumed for the displacement
    // h v (with the old one the bristle spring would lag the motion and pump energy into it). Drives whose
    // current limit engages or lets go at the new velocity are solved again with the other law (a few passes
    // at most: each pass only flips drives whose decision was wrong for the last solve).
    Eigen::VectorXd v_next = v + SolveVelocityChange(*state, v, forces, h);
    for (int pass = 0; pass < kCurrentLimitPasses && LimitCurrents(v, v_next, h, state, &forces); ++pass) {
      v_next = v + SolveVelocityChange(*state, v, forces, h);
    }
    RecordDriveOutputs(v, v_next, h, state);
    // At the configuration the forces were evaluated at.
    if (record_readings) RecordJointWrenches(v, v_next, h, state);
    AdvanceBristles(forces, v_next, h, state);
    multibody_.SetVelocities(v_next, state);
    multibody_.Integrate(v_next, h, state);
  }
  if (record_readings) RecordPadForces(state);
  ClampJointLimits(state);
  UpdateSleep(state, h);
}

void Simulation::HoldDrives(const Forces& first, Forces* later) {
  // A later evaluation in the sub-step keeps the drives' first force and linearisation: the motors' electrical
  // state advances once per sub-step (ActuatorForces).
  later->actuators = first.actuators;
  later->actuator_damping = first.actuator_damping;
  later->actuator_stiffness = first.actuator_stiffness;
  later->tau += first.actuators;
}

void Simulation::RungeKutta4(const Eigen::VectorXd& v, double h, SceneState* state, bool record_readings) {
  // The classic fourth-order Runge–Kutta step on (q, v): stage k sits at q0 + c_k h v_{k−1} (on the configuration
  // manifold, from the step's start, as MuJoCo's RK4 does) with velocity v0 + c_k Δv_{k−1}, c = (½, ½, 1); the step
  // takes the weighted means (1, 2, 2, 1)/6 of the stages' velocities and velocity changes. Contacts are
  // evaluated explicitly at every stage with the bristles of the step's start; the drives keep their
  // start-of-step force (their damping, as in every integrator, inside each stage's solve). For smooth motion:
  // stiff contacts need the linearly implicit step.
  const Forces& first = forces_at_start_;
  stage_start_ = *state;
  Eigen::VectorXd v_prev = v, dv = SolveVelocityChange(*state, v, first, h, &v);
  Eigen::VectorXd v_sum = v, dv_sum = dv;
  for (int k = 1; k < 4; ++k) {
    const double c = k < 3 ? 0.5 : 1.0, weight = k < 3 ? 2.0 : 1.0;
    const Eigen::VectorXd v_k = v + c * dv;
    *state = stage_start_;
    multibody_.Integrate(v_prev, c * h, state);
    FindContacts(state);
    Forces& stage = forces_at_end_;
    ContactForces(*state, v_k, h, &stage);
    HoldDrives(first, &stage);
    dv = SolveVelocityChange(*state, v_k, stage, h, &v_k);
    v_sum += weight * v_k;
    dv_sum += weight * dv;
    v_prev = v_k;
  }
  const Eigen::VectorXd v_next = v + dv_sum / 6;
  *state = stage_start_;
  multibody_.Integrate(v_sum / 6, h, state);
  // With the last stage's contacts, at the step's end.
  if (record_readings) RecordJointWrenches(v, v_next, h, state);
  AdvanceBristles(forces_at_end_, v_next, h, state);
  multibody_.SetVelocities(v_next, state);
}

void Simulation::RecordJointWrenches(const Eigen::VectorXd& v, const Eigen::VectorXd& v_next, double h,
                                     SceneState* state) const {
  // The joint forces of recursive Newton–Euler with the step's accelerations (v_next − v)/h and its contact
  // forces (on body_a; body_b gets the opposite), so the wrenches agree with the step's motion; then from world
  // coordinates about the origin to each joint's child frame.
  if (model_->joints.empty()) return;
  std::vector<Multibody::Vec6> external(model_->bodies.size(), Multibody::Vec6::Zero());
  for (const PairWrench& pair : pair_wrenches_) {  // the contacts' wrenches, summed per pair by ContactForces
    external[pair.body_a] += pair.wrench;
    external[pair.body_b] -= pair.wrench;
  }
  const std::vector<Multibody::Vec6> wrenches =
      multibody_.JointWrenches(*state, v, (v_next - v) / h, params_.gravity, external);
  for (size_t j = 0; j < model_->joints.size(); ++j) {
    const Pose& frame = state->body_poses[model_->joint_bodies.at(j)[1]];
    const Vec3 force = wrenches[j].tail<3>();
    const Vec3 torque = wrenches[j].head<3>() - frame.position.cross(force);  // about the frame's origin
    const Quat world_to_child = frame.orientation.conjugate();
    state->joint_wrenches[j] = {world_to_child * force, world_to_child * torque};
  }
}

Eigen::VectorXd Simulation::SolveVelocityChange(const SceneState& state, const Eigen::VectorXd& v,
                                                const Forces& forces, double h,
                                                const Eigen::VectorXd* bias_velocity) {
  // M Δv = h (τ − b), or with linearised contacts (M − h D − h² K) Δv = h (τ − b) + h² K v (ContactForces
  // gives h D + h² K and h² K v at the sub-step's h). Motors are
  // linearised with every integrator: a geared drive's back-EMF damping is far too stiff for an explicit step.
  // Sleeping free bodies keep zero velocity: their rows are pinned. The matrices are the solve's buffers.
  Eigen::MatrixXd& A = solve_matrix_;
  Eigen::VectorXd& rhs = solve_rhs_;
  multibody_.MassMatrixAndBiasForces(state, params_.gravity, bias_velocity, &A, &rhs);
  rhs = h * (forces.tau - rhs);
  if (forces.contact_matrix.size()) {
    A -= forces.contact_matrix;
    rhs += forces.contact_rhs;
  }
  A.diagonal() -= h * forces.actuator_damping + h * h * forces.actuator_stiffness;
  rhs += h * h * forces.actuator_stiffness.cwiseProduct(v);
  for (size_t body = 0; body < model_->bodies.size(); ++body) {
    const int offset = multibody_.FreeBodyOffset(body);
    if (offset < 0 || !state.sleeping[body]) continue;
    for (int k = offset; k < offset + 6; ++k) {
      A.row(k).setZero();
      A.col(k).setZero();
      A(k, k) = 1;
      rhs[k] = -v[k];
    }
  }
  // The friction–normal coupling (ContactForce::k_slip_normal) makes A non-symmetric: LU, not LDLT.
  solve_lu_.compute(A);
  return solve_lu_.solve(rhs);
}

void Simulation::UpdateSleep(SceneState* state, double h) const {
  // Free bodies slow for sleep_time stop being integrated until something touches them.
  for (size_t body = 0; body < model_->bodies.size(); ++body) {
    if (multibody_.FreeBodyOffset(body) < 0 || state->sleeping[body]) continue;
    const BodyVelocity& velocity = state->body_velocities[body];
    const bool slow = velocity.linear.norm() < params_.sleep_speed && velocity.angular.norm() < params_.sleep_speed;
    state->rest_time[body] = slow ? state->rest_time[body] + h : 0;
    if (params_.sleep_time > 0 && state->rest_time[body] >= params_.sleep_time) {
      state->sleeping[body] = true;
      state->body_velocities[body] = {};
    }
  }
}

void Simulation::ClampJointLimits(SceneState* state) const {
  // A joint at its stop stays there and loses the velocity into the stop (an inelastic end stop), which is
  // what the mechanical stops of a gripper or an arm do.
  bool clamped = false;
  Eigen::VectorXd v = multibody_.Velocities(*state);
  for (size_t j = 0; j < model_->joints.size(); ++j) {
    const JointSpec& joint = model_->joints[j];
    const int offset = multibody_.JointOffset(j);
    const bool limited = joint.type == JointType::kRevolute || joint.type == JointType::kPrismatic;
    if (offset < 0 || !limited) continue;
    double& q = state->joint_positions[j];
    if (q < joint.lower || q > joint.upper) {
      const bool below = q < joint.lower;
      q = below ? joint.lower : joint.upper;
      if (below ? v[offset] < 0 : v[offset] > 0) v[offset] = 0;
      clamped = true;
    }
  }
  if (!clamped) return;
  multibody_.SetVelocities(v, state);
  multibody_.Integrate(Eigen::VectorXd::Zero(v.size()), 0, state);  // followers and link poses from the clamp
}

void Simulation::CheckFinite(const SceneState& state) const {
  const double limit = params_.divergence_speed;
  auto fail = [&](const std::string& what) {
    throw Error(ErrorCode::kFailedPrecondition,
                "simulation diverged at step " + std::to_string(state.step + 1) + ": " + what +
                    "; reduce time_step, raise substeps or use the linearly implicit integrator");
  };
  for (size_t i = 0; i < model_->bodies.size(); ++i) {
    const BodyVelocity& velocity = state.body_velocities[i];
    const Pose& pose = state.body_poses[i];
    if (!pose.position.allFinite() || !pose.orientation.coeffs().allFinite()) {
      fail("body '" + model_->bodies[i].id + "' position " + Vec(pose.position) + " is not finite");
    }
    if (!(velocity.linear.norm() < limit)) {
      fail("body '" + model_->bodies[i].id + "' linear velocity " + Vec(velocity.linear) + " m/s exceeds " +
           FormatNumber(limit));
    }
    if (!(velocity.angular.norm() < limit)) {
      fail("body '" + model_->bodies[i].id + "' angular velocity " + Vec(velocity.angular) + " rad/s exceeds " +
           FormatNumber(limit));
    }
  }
  for (size_t j = 0; j < model_->joints.size(); ++j) {
    if (!std::isfinite(state.joint_positions[j]) || !(std::abs(state.joint_velocities[j]) < limit)) {
      fail("joint '" + model_->joints[j].id + "' position " + FormatNumber(state.joint_positions[j]) +
           ", velocity " + FormatNumber(state.joint_velocities[j]));
    }
  }
  // A NaN or infinity anywhere makes the sum non-finite: one pass of additions, and the culprit looked for only
  // then (a sum of finite values that overflows finds none, and passes).
  Vec3 sum = Vec3::Zero();  // three independent sums: no chain of dependent additions
  for (const auto& entry : state.bristles) sum += entry.second;
  if (std::isfinite(sum.x() + sum.y() + sum.z())) return;
  for (const auto& [key, z] : state.bristles) {
    if (!z.allFinite()) fail("bristle of body '" + model_->bodies[key.body_a].id + "' is " + Vec(z));
  }
}

}  // namespace graspsim
