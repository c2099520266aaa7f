#include "physics/multibody.h"

namespace graspsim {
namespace {


// Spatial cross products for vectors [angular; linear] (Featherstone 2008, §2.9): motion × motion, motion × force.
Vec6 CrossMotion(const Vec6& a, const Vec6& m) {
  const Vec3 w = a.head<3>(), v = a.tail<3>();
  return Stack(w.cross(m.head<3>()), w.cross(m.tail<3>()) + v.cross(m.head<3>()));
}
Vec6 CrossForce(const Vec6& a, const Vec6& f) {
  const Vec3 w = a.head<3>(), v = a.tail<3>();
  return Stack(w.cross(f.head<3>()) + v.cross(f.tail<3>()), w.cross(f.tail<3>()));
}

bool Moves(const JointSpec& joint) { return joint.type != JointType::kFixed; }

}  // namespace

// The recursive algorithms' per-node arrays. A Multibody is shared by every Simulation of its model (one per
// thread at a time): per-thread buffers keep the step free of allocations without a lock.
struct Multibody::Buffers {
  std::vector<Mat6> inertia;  // per node: its child body's spatial inertia (CRBA: the composite one)
  std::vector<Vec6> S, V, A, F;
  Eigen::MatrixXd Mu;
  Eigen::VectorXd u, bu, v;
};

Multibody::Buffers& Multibody::ThreadBuffers() {
  thread_local Buffers buffers;
  return buffers;
}

Multibody::Multibody(const SceneModel& model)
    : model_(model), free_offset_(model.bodies.size(), -1), joint_offset_(model.joints.size(), -1),
      body_node_(model.bodies.size(), -1), mimic_offset_(model.joints.size(), 0),
      leader_(model.joints.size(), -1) {
  for (size_t b = 0; b < model.bodies.size(); ++b) {
    if (model.bodies[b].motion != BodyMotion::kFree) continue;
    free_offset_[b] = nv_;
    nv_ += 6;
  }
  nu_ = nv_;
  // Robot trees: joints in topological order, so a node's parent node exists before it.
  for (const RobotSpec& robot : model.robots) {
    for (const std::string& joint_id : robot.joint_ids) {
      const size_t j = model.joint_index.at(joint_id);
      const JointSpec& joint = model.joints[j];
      Node node;
      node.joint = j;
      node.parent_body = model.body_index.at(joint.parent_body);
      node.parent = body_node_[node.parent_body];
      node.child_body = model.body_index.at(joint.child_body);
      if (Moves(joint)) node.full = nu_++;
      if (Moves(joint) && !joint.mimic) joint_offset_[j] = nv_++;
      body_node_[node.child_body] = static_cast<int>(nodes_.size());
      nodes_.push_back(node);
    }
  }
  // u = G v: free bodies map one to one, each moving joint to its leader (itself when independent).
  full_column_.assign(nu_, -1);
  full_multiplier_.assign(nu_, 0);
  for (size_t b = 0; b < model.bodies.size(); ++b) {
    for (int k = 0; free_offset_[b] >= 0 && k < 6; ++k) {
      full_column_[free_offset_[b] + k] = free_offset_[b] + k;
      full_multiplier_[free_offset_[b] + k] = 1;
    }
  }
  for (const Node& node : nodes_) {
    if (node.full < 0) continue;
    const JointSpec& joint = model.joints[node.joint];
    if (!joint.mimic) {
      leader_[node.joint] = static_cast<int>(node.joint);
      full_column_[node.full] = joint_offset_[node.joint];
      full_multiplier_[node.full] = 1;
      continue;
    }
    const size_t leader = model.joint_index.at(joint.mimic->joint_id);
    if (joint_offset_[leader] < 0) continue;  // a follower of a fixed joint does not move
    leader_[node.joint] = static_cast<int>(leader);
    mimic_offset_[node.joint] = joint.mimic->offset;
    full_column_[node.full] = joint_offset_[leader];
    full_multiplier_[node.full] = joint.mimic->multiplier;
  }
}

Eigen::VectorXd Multibody::Velocities(const SceneState& state) const {
  Eigen::VectorXd v = Eigen::VectorXd::Zero(nv_);
  for (size_t b = 0; b < model_.bodies.size(); ++b) {
    if (free_offset_[b] < 0) continue;
    v.segment<3>(free_offset_[b]) = state.body_velocities[b].linear;
    v.segment<3>(free_offset_[b] + 3) = state.body_velocities[b].angular;
  }
  for (size_t j = 0; j < model_.joints.size(); ++j) {
    if (joint_offset_[j] >= 0) v[joint_offset_[j]] = state.joint_velocities[j];
  }
  return v;
}

Eigen::VectorXd Multibody::FullVelocities(const Eigen::VectorXd& v) const {
  Eigen::VectorXd u;
  FullVelocities(v, &u);
  return u;
}

void Multibody::FullVelocities(const Eigen::VectorXd& v, Eigen::VectorXd* u) const {
  u->resize(nu_);
  for (int i = 0; i < nu_; ++i) (*u)[i] = full_column_[i] < 0 ? 0 : full_multiplier_[i] * v[full_column_[i]];
}

void Multibody::SetVelocities(const Eigen::VectorXd& v, SceneState* state) const {
  for (size_t b = 0; b < model_.bodies.size(); ++b) {
    if (free_offset_[b] < 0) continue;
    state->body_velocities[b].linear = v.segment<3>(free_offset_[b]);
    state->body_velocities[b].angular = v.segment<3>(free_offset_[b] + 3);
  }
  const Eigen::VectorXd u = FullVelocities(v);
  for (const Node& node : nodes_) {
    if (node.full >= 0) state->joint_velocities[node.joint] = u[node.full];
  }
}

Multibody::Vec6 Multibody::MotionSubspace(const SceneState& state, const Node& node) const {
  const JointSpec& joint = model_.joints[node.joint];
  const Pose frame = state.body_poses[node.parent_body] * joint.origin;
  const Vec3 axis = frame.orientation * joint.axis;
  if (joint.type == JointType::kPrismatic) return Stack(Vec3::Zero(), axis);
  return Stack(axis, frame.position.cross(axis));  // velocity of the point at the world origin: ω × (0 − p)
}

Multibody::Mat6 Multibody::SpatialInertia(const SceneState& state, size_t body) const {
  // Featherstone (2.63) about the world origin: [I_c + m c×c×ᵀ, m c×; m c×ᵀ, m 1].
  const Inertial& inertial = model_.bodies[body].inertial;
  const Pose& pose = state.body_poses[body];
  const Mat3 R = pose.orientation.toRotationMatrix();
  const Vec3 c = pose * inertial.center_of_mass;
  const Mat3 cx = Skew(c);
  const double m = inertial.mass;
  Mat6 I;
  I.topLeftCorner<3, 3>() = R * inertial.inertia * R.transpose() + m * cx * cx.transpose();
  I.topRightCorner<3, 3>() = m * cx;
  I.bottomLeftCorner<3, 3>() = m * cx.transpose();
  I.bottomRightCorner<3, 3>() = m * Mat3::Identity();
  return I;
}

Eigen::MatrixXd Multibody::MassMatrix(const SceneState& state) const {
  Eigen::MatrixXd M;
  MassMatrix(state, &M);
  return M;
}

void Multibody::MassMatrix(const SceneState& state, Eigen::MatrixXd* M) const {
  Buffers& buffers = ThreadBuffers();
  NodeKinematics(state, &buffers);
  MassMatrixFrom(state, &buffers, M);
}

Eigen::VectorXd Multibody::BiasForces(const SceneState& state, const Vec3& gravity,
                                      const Eigen::VectorXd* velocities) const {
  Eigen::VectorXd b;
  BiasForces(state, gravity, velocities, &b);
  return b;
}

void Multibody::BiasForces(const SceneState& state, const Vec3& gravity, const Eigen::VectorXd* velocities,
                           Eigen::VectorXd* b) const {
  Buffers& buffers = ThreadBuffers();
  NodeKinematics(state, &buffers);
  BiasForcesFrom(state, gravity, velocities, &buffers, b);
}

void Multibody::MassMatrixAndBiasForces(const SceneState& state, const Vec3& gravity,
                                        const Eigen::VectorXd* velocities, Eigen::MatrixXd* M,
                                        Eigen::VectorXd* b) const {
  Buffers& buffers = ThreadBuffers();
  NodeKinematics(state, &buffers);
  BiasForcesFrom(state, gravity, velocities, &buffers, b);  // first: the mass matrix makes the inertias composite
  MassMatrixFrom(state, &buffers, M);
}

void Multibody::NodeKinematics(const SceneState& state, Buffers* buffers) const {
  buffers->S.resize(nodes_.size());
  buffers->inertia.resize(nodes_.size());
  for (size_t n = 0; n < nodes_.size(); ++n) {
    buffers->S[n] = MotionSubspace(state, nodes_[n]);
    buffers->inertia[n] = SpatialInertia(state, nodes_[n].child_body);
  }
}

void Multibody::MassMatrixFrom(const SceneState& state, Buffers* buffers, Eigen::MatrixXd* M) const {
  Eigen::MatrixXd& Mu = buffers->Mu;
  Mu.setZero(nu_, nu_);
  for (size_t b = 0; b < model_.bodies.size(); ++b) {
    const int o = free_offset_[b];
    if (o < 0) continue;
    const Mat3 R = state.body_poses[b].orientation.toRotationMatrix();
    Mu.block<3, 3>(o, o) = model_.bodies[b].inertial.mass * Mat3::Identity();
    Mu.block<3, 3>(o + 3, o + 3) = R * model_.bodies[b].inertial.inertia * R.transpose();
  }
  // Composite-rigid-body algorithm in world coordinates: each node's subtree inertia, then M_ij = S_iᵀ I^c_j S_j
  // for every ancestor i of j.
  std::vector<Mat6>& composite = buffers->inertia;
  const std::vector<Vec6>& S = buffers->S;
  for (size_t n = nodes_.size(); n-- > 0;) {
    if (nodes_[n].parent >= 0) composite[nodes_[n].parent] += composite[n];
  }
  for (size_t n = 0; n < nodes_.size(); ++n) {
    const int i = nodes_[n].full;
    if (i < 0) continue;
    const Vec6 F = composite[n] * S[n];
    Mu(i, i) = S[n].dot(F);
    for (int a = nodes_[n].parent; a >= 0; a = nodes_[a].parent) {
      const int k = nodes_[a].full;
      if (k < 0) continue;
      Mu(k, i) = Mu(i, k) = S[a].dot(F);
    }
  }
  // Gᵀ M_u G, entry by entry (G has one entry per row at most).
  M->setZero(nv_, nv_);
  for (int i = 0; i < nu_; ++i) {
    const int ci = full_column_[i];
    if (ci < 0) continue;
    for (int k = 0; k < nu_; ++k) {
      const int ck = full_column_[k];
      if (ck >= 0) (*M)(ci, ck) += full_multiplier_[i] * full_multiplier_[k] * Mu(i, k);
    }
  }
}

void Multibody::BiasForcesFrom(const SceneState& state, const Vec3& gravity, const Eigen::VectorXd* velocities,
                               Buffers* buffers, Eigen::VectorXd* b) const {
  if (velocities == nullptr) buffers->v = Velocities(state);
  const Eigen::VectorXd& v = velocities ? *velocities : buffers->v;
  Eigen::VectorXd& bu = buffers->bu;
  bu.setZero(nu_);
  for (size_t body = 0; body < model_.bodies.size(); ++body) {
    const int o = free_offset_[body];
    if (o < 0) continue;
    const Mat3 R = state.body_poses[body].orientation.toRotationMatrix();
    const Vec3 w = v.segment<3>(o + 3);
    bu.segment<3>(o) = -model_.bodies[body].inertial.mass * gravity;
    bu.segment<3>(o + 3) = w.cross(R * (model_.bodies[body].inertial.inertia * (R.transpose() * w)));
  }
  // Recursive Newton–Euler with q̈ = 0 and the base accelerating at −g (which stands in for gravity).
  Eigen::VectorXd& u = buffers->u;
  FullVelocities(v, &u);
  Vec6 base_acceleration;
  base_acceleration = Stack(Vec3::Zero(), -gravity);
  std::vector<Vec6>&V = buffers->V, &A = buffers->A, &F = buffers->F;
  const std::vector<Vec6>& S = buffers->S;
  V.resize(nodes_.size()), A.resize(nodes_.size()), F.resize(nodes_.size());
  for (size_t n = 0; n < nodes_.size(); ++n) {
    const Node& node = nodes_[n];
    const Vec6 parent_velocity = node.parent >= 0 ? V[node.parent] : Vec6::Zero();
    const Vec6 parent_acceleration = node.parent >= 0 ? A[node.parent] : base_acceleration;
    const Vec6 joint_velocity = node.full >= 0 ? Vec6(S[n] * u[node.full]) : Vec6::Zero();
    V[n] = parent_velocity + joint_velocity;
    A[n] = parent_acceleration + CrossMotion(V[n], joint_velocity);
    const Mat6& I = buffers->inertia[n];
    F[n] = I * A[n] + CrossForce(V[n], I * V[n]);
  }
  for (size_t n = nodes_.size(); n-- > 0;) {
    if (nodes_[n].full >= 0) bu[nodes_[n].full] = S[n].dot(F[n]);
    if (nodes_[n].parent >= 0) F[nodes_[n].parent] += F[n];
  }
  // Gᵀ b_u.
  b->setZero(nv_);
  for (int i = 0; i < nu_; ++i) {
    if (full_column_[i] >= 0) (*b)[full_column_[i]] += full_multiplier_[i] * bu[i];
  }
}

std::vector<Multibody::Vec6> Multibody::JointWrenches(const SceneState& state, const Eigen::VectorXd& v,
                                                      const Eigen::VectorXd& a, const Vec3& gravity,
                                                      const std::vector<Vec6>& external) const {
  // Recursive Newton–Euler with the actual joint accelerations (mimic offsets are constant, so ü = G a).
  const Eigen::VectorXd u = FullVelocities(v), ud = FullVelocities(a);
  Vec6 base_acceleration;
  base_acceleration = Stack(Vec3::Zero(), -gravity);
  std::vector<Vec6> V(nodes_.size()), A(nodes_.size()), F(nodes_.size());
  for (size_t n = 0; n < nodes_.size(); ++n) {
    const Node& node = nodes_[n];
    const Vec6 parent_velocity = node.parent >= 0 ? V[node.parent] : Vec6::Zero();
    const Vec6 parent_acceleration = node.parent >= 0 ? A[node.parent] : base_acceleration;
    Vec6 joint_velocity = Vec6::Zero(), joint_acceleration = Vec6::Zero();
    if (node.full >= 0) {
      const Vec6 S = MotionSubspace(state, node);
      joint_velocity = S * u[node.full];
      joint_acceleration = S * ud[node.full];
    }
    V[n] = parent_velocity + joint_velocity;
    A[n] = parent_acceleration + joint_acceleration + CrossMotion(V[n], joint_velocity);
    const Mat6 I = SpatialInertia(state, node.child_body);
    F[n] = I * A[n] + CrossForce(V[n], I * V[n]);
    if (node.child_body < external.size()) F[n] -= external[node.child_body];
  }
  std::vector<Vec6> wrenches(model_.joints.size(), Vec6::Zero());
  for (size_t n = nodes_.size(); n-- > 0;) {
    wrenches[nodes_[n].joint] = F[n];
    if (nodes_[n].parent >= 0) F[nodes_[n].parent] += F[n];
  }
  return wrenches;
}

Multibody::SpatialJacobian Multibody::BodyJacobian(const SceneState& state, size_t body) const {
  SpatialJacobian W;
  BodyJacobian(state, body, &W);
  return W;
}

void Multibody::BodyJacobian(const SceneState& state, size_t body, SpatialJacobian* W) const {
  W->setZero(6, nv_);
  if (const int o = free_offset_[body]; o >= 0) {
    // ω is the body's; the point at the origin moves at v_c + ω × (0 − c) = v_c + [c]× ω.
    const Vec3 c = state.body_poses[body] * model_.bodies[body].inertial.center_of_mass;
    W->block<3, 3>(0, o + 3).setIdentity();
    W->block<3, 3>(3, o).setIdentity();
    W->block<3, 3>(3, o + 3) = Skew(c);
    return;
  }
  for (int n = body_node_[body]; n >= 0; n = nodes_[n].parent) {
    const Node& node = nodes_[n];
    if (node.full < 0 || leader_[node.joint] < 0) continue;
    const int column = joint_offset_[leader_[node.joint]];
    W->col(column) += full_multiplier_[node.full] * MotionSubspace(state, node);
  }
}

Eigen::Matrix3Xd Multibody::PointJacobian(const SceneState& state, size_t body, const Vec3& point) const {
  const SpatialJacobian W = BodyJacobian(state, body);
  return W.bottomRows<3>() - Skew(point) * W.topRows<3>();  // v_O + ω × p = v_O − [p]× ω
}

Vec3 Multibody::PointVelocity(const SceneState& state, size_t body, const Vec3& point) const {
  return PointJacobian(state, body, point) * Velocities(state);
}

void Multibody::Integrate(const Eigen::VectorXd& v, double dt, SceneState* state) const {
  for (size_t b = 0; b < model_.bodies.size(); ++b) {
    const int o = free_offset_[b];
    if (o < 0) continue;
    // The centre of mass moves with v; the orientation turns by exp(ω dt), both about the centre of mass.
    Pose& pose = state->body_poses[b];
    const Vec3 com_local = model_.bodies[b].inertial.center_of_mass;
    const Vec3 com = pose * com_local + dt * v.segment<3>(o);
    const Vec3 rotation = dt * v.segment<3>(o + 3);
    const double angle = rotation.norm();
    if (angle > 0) pose.orientation = (Quat(Eigen::AngleAxisd(angle, rotation / angle)) * pose.orientation).normalized();
    pose.position = com - pose.orientation * com_local;
  }
  for (size_t j = 0; j < model_.joints.size(); ++j) {
    if (joint_offset_[j] >= 0) state->joint_positions[j] += dt * v[joint_offset_[j]];
  }
  for (const Node& node : nodes_) {
    const JointSpec& joint = model_.joints[node.joint];
    if (node.full < 0 || !joint.mimic || leader_[node.joint] < 0) continue;
    state->joint_positions[node.joint] =
        joint.mimic->multiplier * state->joint_positions[leader_[node.joint]] + mimic_offset_[node.joint];
  }
  for (size_t robot = 0; robot < model_.robots.size(); ++robot) UpdateRobotLinkPoses(model_, robot, state);
}

double Multibody::Energy(const SceneState& state, const Vec3& gravity) const {
  const Eigen::VectorXd v = Velocities(state);
  double energy = 0.5 * v.dot(MassMatrix(state) * v);
  for (size_t b = 0; b < model_.bodies.size(); ++b) {
    if (model_.bodies[b].motion == BodyMotion::kStatic) continue;
    const Vec3 com = state.body_poses[b] * model_.bodies[b].inertial.center_of_mass;
    energy -= model_.bodies[b].inertial.mass * gravity.dot(com);
  }
  return energy;
}

}  // namespace graspsim
