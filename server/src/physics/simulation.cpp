#include "physics/simulation.h"

#include <algorithm>
#include <cmath>

#include <Eigen/Cholesky>

#include "core/error.h"
#include "core/format.h"
#include "core/validate.h"

namespace graspsim {
namespace {

// A material's value, or the scene default where the material leaves it at 0.
double Or(double value, double fallback) { return value > 0 ? value : fallback; }

ContactParams BodyContactParams(const Material& material, const ContactParams& defaults) {
  ContactParams params = defaults;
  params.static_friction = material.static_friction;
  params.dynamic_friction = material.dynamic_friction;
  params.stiffness = Or(material.contact_stiffness, defaults.stiffness);
  params.damping = Or(material.contact_damping, defaults.damping);
  params.bristle_stiffness = Or(material.bristle_stiffness, defaults.bristle_stiffness);
  params.bristle_damping = Or(material.bristle_damping, defaults.bristle_damping);
  params.viscous_friction = Or(material.viscous_friction, defaults.viscous_friction);
  params.stribeck_velocity = Or(material.stribeck_velocity, defaults.stribeck_velocity);
  return params;
}

using Mat6 = Eigen::Matrix<double, 6, 6>;

// The bristle of `key` in the sorted vector (zero when the contact has none). Step after step the contacts come
// in the vector's order, so the search starts where the last one ended: O(1) per contact, a binary search only
// where contacts began or ended.
Vec3 BristleAt(const std::vector<std::pair<ContactKey, Vec3>>& bristles, const ContactKey& key, size_t* cursor) {
  if (*cursor < bristles.size() && bristles[*cursor].first == key) return bristles[(*cursor)++].second;
  const auto found = std::lower_bound(bristles.begin(), bristles.end(), key,
                                      [](const auto& entry, const ContactKey& k) { return entry.first < k; });
  *cursor = static_cast<size_t>(found - bristles.begin());
  if (found == bristles.end() || found->first != key) return Vec3::Zero();
  ++*cursor;
  return found->second;
}

// Σ c, Σ c p, Σ c p pᵀ over contact points: what a pair's 6 × 6 block needs of terms that share their 3 × 3
// shape (c I, or c n nᵀ with one normal n), at 9 multiply-adds a point instead of a 6 × 6 outer product.
struct PointMoments {
  double m0 = 0;
  Vec3 m1 = Vec3::Zero();
  Mat3 m2 = Mat3::Zero();
  void Add(double c, const Vec3& p) {
    m0 += c;
    m1 += c * p;
    m2.noalias() += (c * p) * p.transpose();
  }
  // Σ Eᵀ (c I) E = [[c (|p|² I − p pᵀ), c [p]×], [−c [p]×, c I]].
  void AddIsotropicTo(Mat6* A) const {
    A->topLeftCorner<3, 3>() += m2.trace() * Mat3::Identity() - m2;
    A->topRightCorner<3, 3>() += Skew(m1);
    A->bottomLeftCorner<3, 3>() -= Skew(m1);
    A->bottomRightCorner<3, 3>().diagonal().array() += m0;
  }
  // Σ Eᵀ (c n nᵀ) E = Σ c w wᵀ, w = [p × n; n]: [[N m2 Nᵀ, (m1 × n) nᵀ], [n (m1 × n)ᵀ, m0 n nᵀ]], N = [n]×.
  void AddAlongTo(const Vec3& n, Mat6* A) const {
    const Mat3 N = Skew(n);
    const Vec3 moment = m1.cross(n);
    A->topLeftCorner<3, 3>() += N * m2 * N.transpose();
    A->topRightCorner<3, 3>() += moment * n.transpose();
    A->bottomLeftCorner<3, 3>() += n * moment.transpose();
    A->bottomRightCorner<3, 3>() += m0 * n * n.transpose();
  }
};

// A += β w wᵀ with w = [p × u; u]: the 6 × 6 image Eᵀ (β u uᵀ) E of a rank-one 3 × 3 term at point p.
void AddRankOne(const Vec3& point, const Vec3& direction, double beta, Mat6* A) {
  if (beta == 0) return;
  const Vec6 w = Stack(point.cross(direction), direction);
  A->noalias() += (beta * w) * w.transpose();
}

// Extra solves per sub-step to settle which drives are at their current limit (LimitCurrents): a drive settles
// within two (limit → free → the other limit); with several coupled drives the last pass's decision is kept.
constexpr int kCurrentLimitPasses = 4;

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

Simulation::Simulation(std::shared_ptr<const SceneModel> model)
    : model_(std::move(model)),
      params_(model_->simulation),
      multibody_(*model_),
      finder_(*model_, ContactFinderOptions{params_.sample_spacing, 0}),
      pads_(*model_) {
  for (const BodySpec& body : model_->bodies) body_params_.push_back(BodyContactParams(body.material, params_.contact));
  for (const TactileArraySpec& pad : model_->tactile_arrays) {
    // Spring, damper and bristle constants are per texel: a texel's elements share them.
    ContactParams law = pad.contact;
    const double share = 1.0 / pad.ElementsPerTexel();
    for (double* x : {&law.stiffness, &law.damping, &law.bristle_stiffness, &law.bristle_damping, &law.viscous_friction}) {
      *x *= share;
    }
    pad_params_.push_back(law);
    pad_links_.push_back(static_cast<uint32_t>(model_->body_index.at(pad.body_id)));
  }
}

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

StepStats Simulation::Step(SceneState* state, int steps) {
  // Step in place, keeping a copy to restore: a diverged run leaves the caller's state as it was. The copy
  // assignment reuses the buffers of the last call.
  backup_ = *state;
  PrepareState(state);
  const double h = params_.time_step / params_.substeps;
  StepStats stats;
  try {
    for (int s = 0; s < steps; ++s) {
      for (int sub = 0; sub < params_.substeps; ++sub) {
        SubStep(state, h);
        CheckFinite(*state);
      }
      ++state->step;
      state->time += params_.time_step;
    }
  } catch (...) {
    *state = backup_;
    throw;
  }
  stats.contacts = contacts_.size();
  for (size_t i = 0; i < model_->bodies.size(); ++i) {
    stats.awake_bodies += model_->bodies[i].motion == BodyMotion::kFree && !state->sleeping[i];
  }
  return stats;
}

void Simulation::SubStep(SceneState* state, double h) {
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
    second.actuators = forces.actuators;
    second.actuator_damping = forces.actuator_damping;
    second.actuator_stiffness = forces.actuator_stiffness;
    second.tau += forces.actuators;
    const Eigen::VectorXd v_next = v_half + SolveVelocityChange(*state, v_half, second, h / 2);
    RecordJointWrenches(v_half, v_next, h / 2, state);  // the second half kick, at the new configuration
    AdvanceBristles(second, v_half, h, state);
    multibody_.SetVelocities(v_next, state);
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
    RecordJointWrenches(v, v_next, h, state);  // at the configuration the forces were evaluated at
    AdvanceBristles(forces, v_next, h, state);
    multibody_.SetVelocities(v_next, state);
    multibody_.Integrate(v_next, h, state);
  }
  RecordPadForces(state);
  ClampJointLimits(state);
  UpdateSleep(state, h);
}

void Simulation::FindContacts(SceneState* state) {
  // Every sample inside another body. Pairs of bodies that are both asleep or static exert nothing on each
  // other that would change their state, so their contacts are dropped; a touched sleeper wakes up.
  contacts_.clear();
  finder_.Find(state->body_poses, &contacts_);
  auto resting = [&](uint32_t body) {
    return model_->bodies[body].motion == BodyMotion::kStatic || state->sleeping[body];
  };
  std::erase_if(contacts_, [&](const ContactPoint& c) { return resting(c.body_a) && resting(c.body_b); });
  // Contacts come grouped by body pair: the pair's law is combined once per group.
  contact_params_.clear();
  for (size_t i = 0; i < contacts_.size(); ++i) {
    const ContactPoint& c = contacts_[i];
    const bool same_pair = i > 0 && contacts_[i - 1].body_a == c.body_a && contacts_[i - 1].body_b == c.body_b;
    const ContactParams params = same_pair ? contact_params_.back() : PairParams(c.body_a, c.body_b);
    contact_params_.push_back(params);
  }
  AddPadContacts(*state);
  for (const ContactPoint& c : contacts_) {
    if (state->sleeping[c.body_a] || state->sleeping[c.body_b]) {
      state->sleeping[c.body_a] = state->sleeping[c.body_b] = false;
      state->rest_time[c.body_a] = state->rest_time[c.body_b] = 0;
    }
  }
}

void Simulation::AddPadContacts(const SceneState& state) {
  // Each sensing element's segment into the foam: a hit is a soft contact with the pad's own law, acting on the
  // touching body (body_a) and the pad's link (body_b). Pads whose foam touches nothing cast nothing.
  if (model_->tactile_arrays.empty()) return;
  pad_hits_.clear();
  pads_.Cast(state.body_poses, &pad_hits_);
  for (const PadHit& hit : pad_hits_) {
    contacts_.push_back(
        {hit.body, pad_links_[hit.pad], PadFeature(hit.pad, hit.element), hit.point, hit.normal, hit.depth});
    contact_params_.push_back(pad_params_[hit.pad]);
  }
}

void Simulation::RecordPadForces(SceneState* state) const {
  // The reaction on the pad (body_b) of each element's contact force; elements without contact read zero.
  for (std::vector<Vec3>& pad : state->pad_forces) std::fill(pad.begin(), pad.end(), Vec3::Zero());
  for (size_t i = 0; i < contacts_.size(); ++i) {
    const uint64_t feature = contacts_[i].feature;
    if ((feature >> 63) == 0) continue;
    const auto pad = static_cast<uint32_t>((feature >> 32) & 0x7fffffff), element = static_cast<uint32_t>(feature);
    state->pad_forces[pad][element] = -forces_[i];
  }
}

void Simulation::RecordJointWrenches(const Eigen::VectorXd& v, const Eigen::VectorXd& v_next, double h,
                                     SceneState* state) const {
  // The joint forces of recursive Newton–Euler with the step's accelerations (v_next − v)/h and its contact
  // forces (on body_a; body_b gets the opposite), so the wrenches agree with the step's motion; then from world
  // coordinates about the origin to each joint's child frame.
  if (model_->joints.empty()) return;
  std::vector<Multibody::Vec6> external(model_->bodies.size(), Multibody::Vec6::Zero());
  for (size_t i = 0; i < contacts_.size(); ++i) {
    const Vec6 wrench = Stack(contacts_[i].point.cross(forces_[i]), forces_[i]);
    external[contacts_[i].body_a] += wrench;
    external[contacts_[i].body_b] -= wrench;
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

void Simulation::ContactForces(const SceneState& state, const Eigen::VectorXd& v, double h, Forces* forces) {
  // Penalty normal force and LuGre friction at each point, mapped to generalised forces, with their stiffness
  // and damping for the linearly implicit solve.
  const int nv = multibody_.velocity_count();
  forces->tau.setZero(nv);
  forces->actuators.setZero(nv);
  forces->actuator_damping.setZero(nv);
  forces->actuator_stiffness.setZero(nv);
  const bool linearize = params_.integrator == Integrator::kLinearlyImplicitEuler;
  if (linearize) {
    forces->contact_matrix.setZero(nv, nv);
    forces->contact_rhs.setZero(nv);
  } else {
    forces->contact_matrix.resize(0, 0);
    forces->contact_rhs.resize(0);
  }
  const size_t n = contacts_.size();
  forces->normal_force.resize(n);
  forces->contact_pair.resize(n);
  forces->bristle.resize(n);
  forces->pair_jacobians.clear();
  forces_.resize(n);
  // Pair by pair: each contact's force becomes a wrench about the world origin, [p × f; f]; its linearisation
  // (h D + h² K, in the scalar form of ContactForce) becomes the 6 × 6 block Eᵀ (h D + h² K) E with
  // E(p) = [−[p]×, 1], summed as moments where terms share their shape and as rank-one updates otherwise; only
  // the pair's sums meet the nv-sized Jacobian (nv² work per pair instead of per contact).
  size_t cursor = 0;  // into state.bristles, which is in the contacts' order
  for (size_t begin = 0; begin < n;) {
    const uint32_t a = contacts_[begin].body_a, b = contacts_[begin].body_b;
    size_t end = begin;
    while (end < n && contacts_[end].body_a == a && contacts_[end].body_b == b) ++end;
    const size_t pair = forces->pair_jacobians.size();
    const Multibody::SpatialJacobian& W = forces->pair_jacobians.emplace_back(
        multibody_.BodyJacobian(state, a) - multibody_.BodyJacobian(state, b));
    const Vec6 twist = W * v;
    Vec3 force_sum = Vec3::Zero(), moment_sum = Vec3::Zero();
    Mat6 block = Mat6::Zero();
    Vec6 stiffness_twist = Vec6::Zero();  // Σ Eᵀ K (E twist), for h² K v
    // The isotropic terms, and the normal terms of the contacts that share the pair's first normal (all of a
    // flat pad's elements, a face lying on a face), as moments; the rest as rank-one updates.
    PointMoments isotropic, along_normal;
    const Vec3 shared_normal = contacts_[begin].normal;
    for (size_t i = begin; i < end; ++i) {
      const ContactPoint& c = contacts_[i];
      const Vec3 z = forces->bristle[i] = BristleAt(state.bristles, ContactKey{a, b, c.feature}, &cursor);
      const Vec3 relative = twist.tail<3>() + twist.head<3>().cross(c.point);
      const ContactForce f = EvaluateContact(contact_params_[i], c.depth, c.normal, relative, z, h);
      forces->normal_force[i] = f.normal_force;
      forces->contact_pair[i] = pair;
      forces_[i] = f.force;
      force_sum += f.force;
      moment_sum += c.point.cross(f.force);
      if (!linearize) continue;
      isotropic.Add(h * f.d_iso + h * h * f.k_iso, c.point);
      const double along = h * f.d_normal + h * h * f.k_normal;
      if (c.normal == shared_normal) {
        along_normal.Add(along, c.point);
      } else {
        AddRankOne(c.point, c.normal, along, &block);
      }
      AddRankOne(c.point, f.slip_direction, h * h * f.k_slip, &block);
      const Vec3 k_relative = f.k_iso * relative + f.k_normal * c.normal.dot(relative) * c.normal +
                              f.k_slip * f.slip_direction.dot(relative) * f.slip_direction;
      stiffness_twist.head<3>() += c.point.cross(k_relative);
      stiffness_twist.tail<3>() += k_relative;
    }
    forces->tau.noalias() += W.transpose() * Stack(moment_sum, force_sum);
    if (!linearize) {
      begin = end;
      continue;
    }
    isotropic.AddIsotropicTo(&block);
    along_normal.AddAlongTo(shared_normal, &block);
    forces->contact_matrix.noalias() += W.transpose() * (block * W);
    forces->contact_rhs.noalias() += (h * h) * (W.transpose() * stiffness_twist);
    begin = end;
  }
}

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
  // The current limit is decided at the step's new velocity, not its start: the free (unlimited) drive force
  // there, by the linearisation the solve used, is f + D (v⁺ − v) + K h v⁺. A drive whose decision changes is
  // stepped again from its state before the step with the other law, and its force and derivatives in *forces
  // are replaced. Returns whether any changed (the caller solves again).
  bool changed = false;
  for (Drive& drive : drives_) {
    const ActuatorOutput& out = drive.output;
    const int o = drive.offset;
    const double free_force = out.free_force + out.free_damping * (v_next[o] - v[o]) + out.free_stiffness * h * v_next[o];
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
    const double force = std::clamp(out.free_force + out.free_damping * (v_next[o] - v[o]) +
                                        out.free_stiffness * h * v_next[o],
                                    -out.force_limit, out.force_limit);
    JointActuator& actuator = state->actuators.at(drive.joint);
    const DcMotorParams& motor = actuator.motor;
    actuator.state.current = force / (motor.ratio * motor.efficiency * motor.torque_constant);  // > 0: force_limit > 0
    actuator.joint_force = force;
  }
}

Eigen::VectorXd Simulation::SolveVelocityChange(const SceneState& state, const Eigen::VectorXd& v,
                                                const Forces& forces, double h) const {
  // M Δv = h (τ − b), or with linearised contacts (M − h D − h² K) Δv = h (τ − b) + h² K v (ContactForces
  // gives h D + h² K and h² K v at the sub-step's h). Motors are
  // linearised with every integrator: a geared drive's back-EMF damping is far too stiff for an explicit step.
  // Sleeping free bodies keep zero velocity: their rows are pinned.
  Eigen::MatrixXd A = multibody_.MassMatrix(state);
  Eigen::VectorXd rhs = h * (forces.tau - multibody_.BiasForces(state, params_.gravity));
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
  return A.ldlt().solve(rhs);
}

void Simulation::AdvanceBristles(const Forces& forces, const Eigen::VectorXd& v, double h, SceneState* state) {
  // The exact LuGre update, with the slip velocity the friction force was evaluated with. Contacts that ended
  // drop their bristle state; frictionless contacts never get one. Built in the contacts' (sorted) order into
  // the previous step's buffer.
  std::vector<std::pair<ContactKey, Vec3>>& bristles = spare_bristles_;
  bristles.clear();
  twists_.clear();
  for (const Multibody::SpatialJacobian& W : forces.pair_jacobians) twists_.push_back(W * v);
  for (size_t i = 0; i < contacts_.size(); ++i) {
    const ContactPoint& c = contacts_[i];
    const ContactParams& params = contact_params_[i];
    if (!params.HasFriction()) continue;
    const Vec6& twist = twists_[forces.contact_pair[i]];
    const Vec3 relative = twist.tail<3>() + twist.head<3>().cross(c.point);
    bristles.emplace_back(ContactKey{c.body_a, c.body_b, c.feature},
                          AdvanceBristle(params, forces.normal_force[i], c.normal, relative, forces.bristle[i], h));
  }
  auto by_key = [](const auto& x, const auto& y) { return x.first < y.first; };
  if (!std::is_sorted(bristles.begin(), bristles.end(), by_key)) std::sort(bristles.begin(), bristles.end(), by_key);
  std::swap(state->bristles, bristles);
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
  for (const auto& [key, z] : state.bristles) {
    if (!z.allFinite()) fail("bristle of body '" + model_->bodies[key.body_a].id + "' is " + Vec(z));
  }
}

}  // namespace graspsim
