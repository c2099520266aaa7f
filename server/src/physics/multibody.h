// The scene's degrees of freedom and their dynamics, in generalised velocities v:
//   - each free body: 6 entries, the world-frame linear velocity of its centre of mass, then its world-frame
//     angular velocity (BodyVelocity in SceneState);
//   - each robot: one entry per independent joint (revolute, continuous, prismatic; mimic joints are not
//     independent: q_follower = multiplier · q_leader + offset). The base is welded to the world at its pose.
//   Static bodies and fixed joints have none.
// Equations of motion: M(q) v̇ = τ + Σ J_iᵀ f_i − b(q, v), with M from the composite-rigid-body algorithm and
// b (Coriolis, centrifugal, gyroscopic and gravity terms) from the recursive Newton–Euler algorithm
// (Featherstone, Rigid Body Dynamics Algorithms, 2008, ch. 5–6), mimic joints folded in by q = G q_r + c:
// M_r = Gᵀ M G, b_r = Gᵀ b. Free bodies: M = diag(m 1, I_world), b = (−m g, ω × I_world ω).
#pragma once

#include <vector>

#include <Eigen/Core>

#include "core/math.h"
#include "world/model.h"
#include "world/state.h"

namespace graspsim {

class Multibody {
 public:
  // `model` must outlive this object.
  explicit Multibody(const SceneModel& model);

  int velocity_count() const { return nv_; }
  // The first generalised velocity of a body's free block or a robot's joint block; -1 if it has none.
  int FreeBodyOffset(size_t body) const { return free_offset_[body]; }
  // Index into v of an independent joint, or -1 (fixed or mimic joint).
  int JointOffset(size_t joint) const { return joint_offset_[joint]; }

  // v from the state (free-body velocities, leader joint velocities) and back; SetVelocities also sets the
  // mimic followers' velocities.
  Eigen::VectorXd Velocities(const SceneState& state) const;
  void SetVelocities(const Eigen::VectorXd& v, SceneState* state) const;

  // M(q), nv × nv, symmetric positive definite (block diagonal across free bodies and robots).
  Eigen::MatrixXd MassMatrix(const SceneState& state) const;
  // The same into *M, reusing its buffer (a work cycle's step: no allocation).
  void MassMatrix(const SceneState& state, Eigen::MatrixXd* M) const;
  // b(q, v) with gravity g (m/s², world); v from the state unless `velocities` is given.
  Eigen::VectorXd BiasForces(const SceneState& state, const Vec3& gravity,
                             const Eigen::VectorXd* velocities = nullptr) const;
  void BiasForces(const SceneState& state, const Vec3& gravity, const Eigen::VectorXd* velocities,
                  Eigen::VectorXd* b) const;
  // Both, from one pass of the joints' motion subspaces and the links' spatial inertias (a step needs both).
  void MassMatrixAndBiasForces(const SceneState& state, const Vec3& gravity, const Eigen::VectorXd* velocities,
                               Eigen::MatrixXd* M, Eigen::VectorXd* b) const;
  // W (6 × nv) such that W v = [ω; v_O], the body's angular velocity and the velocity of the body-fixed point at
  // the world origin (Featherstone's spatial velocity, world coordinates). A point p then moves at
  // v_O + ω × p. Zero for static bodies; a link's depends on every joint between the robot base and the link.
  using SpatialJacobian = Eigen::Matrix<double, 6, Eigen::Dynamic>;
  SpatialJacobian BodyJacobian(const SceneState& state, size_t body) const;
  // The same into *W, reusing its buffer (a step's contact pairs: no allocation).
  void BodyJacobian(const SceneState& state, size_t body, SpatialJacobian* W) const;
  // J (3 × nv) such that the world velocity of the point fixed to `body` at world position `point` is J v.
  Eigen::Matrix3Xd PointJacobian(const SceneState& state, size_t body, const Vec3& point) const;
  Vec3 PointVelocity(const SceneState& state, size_t body, const Vec3& point) const;

  // q ← q + dt · v on the configuration manifold (free-body orientations by the exponential map, kept
  // normalised), followers from their leaders, then every robot link placed by forward kinematics.
  void Integrate(const Eigen::VectorXd& v, double dt, SceneState* state) const;

  // The spatial force each joint transmits from its parent side to its child side (Featherstone's joint force
  // f_i: what the child's subtree receives through the joint), [torque about the world origin; force], world
  // coordinates, per joint (zero for joints of no robot). By the backward pass of recursive Newton–Euler:
  // f_n = I_n A_n + V_n ×* I_n V_n − f_ext,n summed over the subtree, with the velocities v, the generalised
  // accelerations a = v̇, the base accelerating at −g, and `external` the wrenches [torque about the world origin;
  // force] (world) on each body from outside the tree (contacts), per body.
  using Vec6 = graspsim::Vec6;
  std::vector<Vec6> JointWrenches(const SceneState& state, const Eigen::VectorXd& v, const Eigen::VectorXd& a,
                                  const Vec3& gravity, const std::vector<Vec6>& external) const;

  // Total mechanical energy (kinetic + gravitational potential), J; for tests and drift checks.
  double Energy(const SceneState& state, const Vec3& gravity) const;

 private:
  // A moving joint of a robot's tree, in topological order across all robots.
  struct Node {
    size_t joint = 0;
    int parent = -1;      // the node whose child is this joint's parent body; -1 at the welded base
    size_t parent_body = 0, child_body = 0;
    int full = -1;        // index into the full velocity vector u (every moving joint, mimic ones included)
  };
  using Mat6 = Eigen::Matrix<double, 6, 6>;

  // Joint motion subspace [ω; v at the world origin] in world coordinates.
  Vec6 MotionSubspace(const SceneState& state, const Node& node) const;
  // Spatial inertia of a body about the world origin, world coordinates.
  Mat6 SpatialInertia(const SceneState& state, size_t body) const;
  // Per-thread working arrays of the recursive algorithms (multibody.cpp).
  struct Buffers;
  static Buffers& ThreadBuffers();
  // Each node's motion subspace and its child body's spatial inertia, at the state's configuration.
  void NodeKinematics(const SceneState& state, Buffers* buffers) const;
  // CRBA and RNEA from NodeKinematics; the first turns the inertias into composite ones.
  void MassMatrixFrom(const SceneState& state, Buffers* buffers, Eigen::MatrixXd* M) const;
  void BiasForcesFrom(const SceneState& state, const Vec3& gravity, const Eigen::VectorXd* velocities,
                      Buffers* buffers, Eigen::VectorXd* b) const;
  // The joint velocities u of every moving joint (u = G v).
  Eigen::VectorXd FullVelocities(const Eigen::VectorXd& v) const;
  void FullVelocities(const Eigen::VectorXd& v, Eigen::VectorXd* u) const;

  const SceneModel& model_;
  int nv_ = 0, nu_ = 0;            // reduced and full velocity counts
  std::vector<int> free_offset_;   // per body
  std::vector<int> joint_offset_;  // per joint
  std::vector<Node> nodes_;        // fixed joints too (full = -1), so links welded to links are carried
  std::vector<int> body_node_;     // per body: the node whose child it is, or -1
  // u = G v (nu × nv: identity on free bodies, multipliers for mimic joints). G has at most one entry per row, so
  // it is kept as that entry's column (-1: none) and value; M = Gᵀ M_u G and b = Gᵀ b_u are scattered by it.
  std::vector<int> full_column_;
  std::vector<double> full_multiplier_;
  std::vector<double> mimic_offset_;  // per joint: q = multiplier · q_leader + offset (followers only)
  std::vector<int> leader_;           // per joint: its independent leader joint (itself when independent)
};

}  // namespace graspsim
