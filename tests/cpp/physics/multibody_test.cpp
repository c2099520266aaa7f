// Multibody dynamics against independent references: the mass matrix against the kinetic energy of the
// forward-kinematics poses, the point Jacobian against moved points, the bias forces against the potential
// energy and Lagrange's equations, M and b together against energy conservation, and a pendulum in closed form.
#include "physics/multibody.h"

#include <cmath>
#include <functional>
#include <random>
#include <vector>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <gtest/gtest.h>

#include "test_bodies.h"

namespace graspsim {
namespace {

// Central differences: truncation ~ε² ≈ 1e-10, rounding ~1e-16/ε ≈ 1e-11, both far below the tolerances.
constexpr double kEps = 1e-5;
const Vec3 kGravity(0, 0, -9.81);

Quat Exp(const Vec3& rotation) {
  const double angle = rotation.norm();
  return angle > 0 ? Quat(Eigen::AngleAxisd(angle, rotation / angle)) : Quat::Identity();
}

Mat3 Skew(const Vec3& w) {
  Mat3 m;
  m << 0, -w.z(), w.y(), w.z(), 0, -w.x(), -w.y(), w.x(), 0;
  return m;
}

// A body with its centre of mass off the frame origin and principal axes turned away from the frame's, so
// its inertia tensor is full.
BodySpec Body(const std::string& id, BodyMotion motion, double mass, const Vec3& com, const Vec3& principal,
              const Quat& axes) {
  BodySpec body;
  body.id = id;
  body.robot_id = motion == BodyMotion::kArticulated ? id.substr(0, id.find('/')) : "";
  body.motion = motion;
  body.inertial.mass = mass;
  body.inertial.center_of_mass = com;
  const Mat3 R = axes.toRotationMatrix();
  body.inertial.inertia = R * principal.asDiagonal() * R.transpose();
  return body;
}

using test_objects::RobotJoint;

// Followers from their leaders by the mimic rule, then the links by forward kinematics.
void PlaceLinks(const SceneModel& model, SceneState* state) {
  for (size_t j = 0; j < model.joints.size(); ++j) {
    if (const auto& mimic = model.joints[j].mimic) {
      state->joint_positions[j] =
          mimic->multiplier * state->joint_positions[model.joint_index.at(mimic->joint_id)] + mimic->offset;
    }
  }
  for (size_t robot = 0; robot < model.robots.size(); ++robot) UpdateRobotLinkPoses(model, robot, state);
}

// The configuration q ⊕ x, written here rather than taken from Multibody::Integrate: a free body's centre of
// mass moves by x_linear and it turns by exp(x_angular) about it (world frame); independent joints add x.
SceneState Place(const SceneModel& model, const Multibody& mb, const SceneState& reference,
                 const Eigen::VectorXd& x) {
  SceneState state = reference;
  for (size_t b = 0; b < model.bodies.size(); ++b) {
    const int o = mb.FreeBodyOffset(b);
    if (o < 0) continue;
    const Vec3 com_local = model.bodies[b].inertial.center_of_mass;
    Pose& pose = state.body_poses[b];
    const Vec3 com = pose * com_local + x.segment<3>(o);
    pose.orientation = (Exp(x.segment<3>(o + 3)) * pose.orientation).normalized();
    pose.position = com - pose.orientation * com_local;
  }
  for (size_t j = 0; j < model.joints.size(); ++j) {
    if (mb.JointOffset(j) >= 0) state.joint_positions[j] += x[mb.JointOffset(j)];
  }
  PlaceLinks(model, &state);
  return state;
}

// Kinetic energy Σ ½ m |ċ|² + ½ ωᵀ I_world ω along q ⊕ t v at t = 0, every body's velocity from central
// differences of its world pose.
double KineticEnergyByDifferences(const SceneModel& model, const Multibody& mb, const SceneState& state,
                                  const Eigen::VectorXd& v) {
  const SceneState plus = Place(model, mb, state, kEps * v), minus = Place(model, mb, state, -kEps * v);
  double energy = 0;
  for (size_t b = 0; b < model.bodies.size(); ++b) {
    const Inertial& inertial = model.bodies[b].inertial;
    const Vec3 com_velocity =
        (plus.body_poses[b] * inertial.center_of_mass - minus.body_poses[b] * inertial.center_of_mass) / (2 * kEps);
    const Mat3 R = state.body_poses[b].orientation.toRotationMatrix();
    const Mat3 W = (plus.body_poses[b].orientation.toRotationMatrix() -
                    minus.body_poses[b].orientation.toRotationMatrix()) / (2 * kEps) * R.transpose();  // Ṙ Rᵀ = ω×
    const Vec3 w = 0.5 * Vec3(W(2, 1) - W(1, 2), W(0, 2) - W(2, 0), W(1, 0) - W(0, 1));
    energy += 0.5 * inertial.mass * com_velocity.squaredNorm() + 0.5 * w.dot(R * inertial.inertia * R.transpose() * w);
  }
  return energy;
}

// −Σ m g·c over the bodies that can move (as Multibody::Energy counts it).
double PotentialEnergy(const SceneModel& model, const SceneState& state) {
  double energy = 0;
  for (size_t b = 0; b < model.bodies.size(); ++b) {
    if (model.bodies[b].motion == BodyMotion::kStatic) continue;
    energy -= model.bodies[b].inertial.mass * kGravity.dot(state.body_poses[b] * model.bodies[b].inertial.center_of_mass);
  }
  return energy;
}

// ∂f/∂x_i at x = 0 by central differences.
Eigen::VectorXd Gradient(int n, const std::function<double(const Eigen::VectorXd&)>& f) {
  Eigen::VectorXd gradient(n);
  for (int i = 0; i < n; ++i) {
    const Eigen::VectorXd e = kEps * Eigen::VectorXd::Unit(n, i);
    gradient[i] = (f(e) - f(-e)) / (2 * kEps);
  }
  return gradient;
}

Eigen::VectorXd RandomVector(int n, std::mt19937* rng) {
  std::uniform_real_distribution<double> uniform(-1, 1);
  Eigen::VectorXd v(n);
  for (int i = 0; i < n; ++i) v[i] = uniform(*rng);
  return v;
}

// SO(3)'s left Jacobian: the world angular velocity of exp(θ) R0 is J_l(θ) θ̇.
Mat3 LeftJacobian(const Vec3& theta) {
  const double a = theta.norm();
  const Mat3 t = Skew(theta);
  if (a < 1e-8) return Mat3::Identity() + 0.5 * t;
  return Mat3::Identity() + (1 - std::cos(a)) / (a * a) * t + (a - std::sin(a)) / (a * a * a) * t * t;
}

// A static table; a robot welded at a turned pose with a branched tree: base → j1 (revolute) → l1 → j2
// (prismatic) → l2 → j3 (revolute) → l3 → j6 (continuous, mimics j1 below it in the chain) → l6, with
// l2 → j7 (fixed) → l7 welded to a moving link, and base → j4 (fixed) → l4 → j5 (revolute, mimics j1 on the
// other branch) → l5; a free box, turned. The joints are stored out of topological order, axes off the
// coordinate axes, origins offset and turned; every inertia is full and every centre of mass off its origin.
class MultibodyTest : public ::testing::Test {
 protected:
  static constexpr size_t kBox = 9;  // the free body, last of the bodies

  static SceneModel ArmModel() {
    SceneModel model;
    const Quat I = Quat::Identity();
    model.bodies = {
        Body("table", BodyMotion::kStatic, 10, Vec3::Zero(), Vec3(1, 1, 1), I),
        Body("arm/base", BodyMotion::kArticulated, 2, Vec3(0.01, 0, 0.02), Vec3(0.01, 0.01, 0.01), I),
        Body("arm/l1", BodyMotion::kArticulated, 1.2, Vec3(0.05, 0.02, 0.15), Vec3(0.02, 0.025, 0.03),
             QuatFromRpy(0.3, 0.2, -0.5)),
        Body("arm/l2", BodyMotion::kArticulated, 0.8, Vec3(-0.03, 0.04, 0.1), Vec3(0.01, 0.012, 0.015),
             QuatFromRpy(-0.4, 0.6, 0.1)),
        Body("arm/l3", BodyMotion::kArticulated, 0.5, Vec3(0.02, -0.06, 0.04), Vec3(0.004, 0.005, 0.007),
             QuatFromRpy(1.0, -0.2, 0.3)),
        Body("arm/l4", BodyMotion::kArticulated, 0.6, Vec3(0, 0.05, -0.02), Vec3(0.006, 0.006, 0.009),
             QuatFromRpy(0.2, 0.4, 0.6)),
        Body("arm/l5", BodyMotion::kArticulated, 0.3, Vec3(0.04, 0, 0.03), Vec3(0.002, 0.003, 0.004),
             QuatFromRpy(-0.3, 0.1, 0.8)),
        Body("arm/l6", BodyMotion::kArticulated, 0.25, Vec3(0.03, 0.02, -0.01), Vec3(0.001, 0.0015, 0.002),
             QuatFromRpy(0.7, -0.5, 0.2)),
        Body("arm/l7", BodyMotion::kArticulated, 0.2, Vec3(0.01, 0.03, 0), Vec3(0.001, 0.002, 0.0025),
             QuatFromRpy(-0.6, 0.3, 0.9)),
        Body("box", BodyMotion::kFree, 1.5, Vec3(0.02, -0.01, 0.03), Vec3(0.01, 0.02, 0.025),
             QuatFromRpy(0.5, -0.7, 0.2)),
    };
    model.joints = {
        RobotJoint("arm/j1", JointType::kRevolute, "arm/base", "arm/l1", {Vec3(0.1, -0.05, 0.2), QuatFromRpy(0.3, -0.2, 0.5)},
              Vec3(1, 2, 3)),
        RobotJoint("arm/j2", JointType::kPrismatic, "arm/l1", "arm/l2", {Vec3(0, 0.05, 0.3), QuatFromRpy(0.1, 0.2, 0)},
              Vec3(0.2, 1, -0.4)),
        RobotJoint("arm/j3", JointType::kRevolute, "arm/l2", "arm/l3", {Vec3(0.02, 0, 0.25), QuatFromRpy(-0.5, 0.3, 0.2)},
              Vec3(0, -1, 1)),
        RobotJoint("arm/j4", JointType::kFixed, "arm/base", "arm/l4", {Vec3(-0.1, 0.1, 0.05), QuatFromRpy(0.6, 0, -0.4)},
              Vec3::UnitX()),
        RobotJoint("arm/j5", JointType::kRevolute, "arm/l4", "arm/l5", {Vec3(0.05, 0, 0.15), QuatFromRpy(0.2, -0.1, 0)},
              Vec3(-1, 0.5, 0.2), MimicSpec{"arm/j1", -0.7, 0.1}),
        RobotJoint("arm/j6", JointType::kContinuous, "arm/l3", "arm/l6", {Vec3(0, 0.1, 0.05), QuatFromRpy(0, 0.5, -0.3)},
              Vec3(1, 0, 1), MimicSpec{"arm/j1", 1.3, -0.2}),
        RobotJoint("arm/j7", JointType::kFixed, "arm/l2", "arm/l7", {Vec3(0.04, -0.03, 0.1), QuatFromRpy(0.2, 0.5, -0.1)},
              Vec3::UnitX()),
    };
    model.robots = {RobotSpec{"arm", "test", "arm/base",
                              {"arm/base", "arm/l1", "arm/l2", "arm/l7", "arm/l3", "arm/l6", "arm/l4", "arm/l5"},
                              {"arm/j1", "arm/j2", "arm/j7", "arm/j3", "arm/j6", "arm/j4", "arm/j5"}, {}}};
    model.Reindex();
    return model;
  }

  static SceneState ArmState(const SceneModel& model) {
    SceneState state;
    state.body_poses.resize(model.bodies.size());
    state.body_velocities.resize(model.bodies.size());
    state.body_poses[1] = {Vec3(0.2, -0.1, 0.5), QuatFromRpy(0.4, -0.3, 1.1)};
    state.body_poses[kBox] = {Vec3(0.5, 0.3, 1.0), QuatFromRpy(0.3, 1.0, -0.6)};
    state.joint_positions = {0.4, 0.05, -0.8, 0, 0, 0, 0};
    state.joint_velocities.resize(model.joints.size());
    PlaceLinks(model, &state);
    return state;
  }

  // The robot's generalised velocities (the Lagrange check applies to true coordinates only, not to the
  // free body's angular velocity).
  std::vector<int> JointDofs() const {
    std::vector<int> dofs;
    for (size_t j = 0; j < model.joints.size(); ++j) {
      if (mb.JointOffset(j) >= 0) dofs.push_back(mb.JointOffset(j));
    }
    return dofs;
  }

  SceneModel model = ArmModel();
  SceneState state = ArmState(model);
  Multibody mb{model};
  std::mt19937 rng{12345};
};

TEST_F(MultibodyTest, CountsOffsetsAndMimicFollowers) {
  // 6 for the box, one each for j1, j2, j3; the fixed j4, j7 and the followers j5, j6 have none.
  EXPECT_EQ(mb.velocity_count(), 6 + 3);
  EXPECT_EQ(mb.FreeBodyOffset(kBox), 0);
  EXPECT_EQ(mb.FreeBodyOffset(0), -1);
  EXPECT_EQ(mb.FreeBodyOffset(2), -1);
  for (size_t j : {3u, 4u, 5u, 6u}) EXPECT_EQ(mb.JointOffset(j), -1) << model.joints[j].id;
  for (size_t j : {0u, 1u, 2u}) EXPECT_GE(mb.JointOffset(j), 6) << model.joints[j].id;

  const Eigen::VectorXd v = RandomVector(mb.velocity_count(), &rng);
  mb.SetVelocities(v, &state);
  EXPECT_EQ(mb.Velocities(state), v);
  const double leader_velocity = v[mb.JointOffset(0)];
  EXPECT_NEAR(state.joint_velocities[4], -0.7 * leader_velocity, 1e-12);
  EXPECT_NEAR(state.joint_velocities[5], 1.3 * leader_velocity, 1e-12);
  EXPECT_EQ(state.joint_velocities[3], 0);
  EXPECT_EQ(state.joint_velocities[6], 0);

  mb.Integrate(v, 0.37, &state);
  const double leader = state.joint_positions[0];
  EXPECT_NEAR(leader, 0.4 + 0.37 * leader_velocity, 1e-12);
  EXPECT_NEAR(state.joint_positions[4], -0.7 * leader + 0.1, 1e-12);
  EXPECT_NEAR(state.joint_positions[5], 1.3 * leader - 0.2, 1e-12);
  EXPECT_EQ(state.joint_positions[3], 0);
  EXPECT_EQ(state.joint_positions[6], 0);
}

TEST_F(MultibodyTest, MassMatrixIsTheHessianOfKineticEnergy) {
  const Eigen::MatrixXd M = mb.MassMatrix(state);
  EXPECT_LE((M - M.transpose()).norm(), 1e-12 * M.norm());
  EXPECT_GT(Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(M).eigenvalues().minCoeff(), 0);
  for (int trial = 0; trial < 10; ++trial) {
    const Eigen::VectorXd v = RandomVector(mb.velocity_count(), &rng);
    const double kinetic = KineticEnergyByDifferences(model, mb, state, v);
    EXPECT_NEAR(0.5 * v.dot(M * v) / kinetic, 1, 1e-6) << "trial " << trial;
    mb.SetVelocities(v, &state);
    EXPECT_NEAR(mb.Energy(state, kGravity) / (kinetic + PotentialEnergy(model, state)), 1, 1e-6);
  }
}

TEST_F(MultibodyTest, PointJacobianMatchesMovedPoints) {
  const Vec3 local(0.03, -0.02, 0.05);
  for (int trial = 0; trial < 3; ++trial) {
    const Eigen::VectorXd v = RandomVector(mb.velocity_count(), &rng);
    mb.SetVelocities(v, &state);
    SceneState plus = state, minus = state;
    mb.Integrate(v, kEps, &plus);
    mb.Integrate(v, -kEps, &minus);
    // Every body: the table and the welded base must come out exactly zero (the difference is zero there).
    for (size_t b = 0; b < model.bodies.size(); ++b) {
      const Vec3 point = state.body_poses[b] * local;
      const Vec3 expected = (plus.body_poses[b] * local - minus.body_poses[b] * local) / (2 * kEps);
      const Vec3 actual = mb.PointJacobian(state, b, point) * v;
      EXPECT_LE((actual - expected).norm(), 1e-7 * expected.norm()) << model.bodies[b].id;
      EXPECT_LE((mb.PointVelocity(state, b, point) - actual).norm(), 1e-14 * (1 + actual.norm()));
    }
  }
}

TEST_F(MultibodyTest, BiasAtRestIsTheGradientOfPotentialEnergy) {
  const int n = mb.velocity_count();
  mb.SetVelocities(Eigen::VectorXd::Zero(n), &state);
  const Eigen::VectorXd b = mb.BiasForces(state, kGravity);
  // Perturbing the leaders only (followers by the mimic rule) differentiates along the reduced coordinates.
  const Eigen::VectorXd expected =
      Gradient(n, [&](const Eigen::VectorXd& x) { return PotentialEnergy(model, Place(model, mb, state, x)); });
  EXPECT_LE((b - expected).norm(), 1e-7 * expected.norm()) << b.transpose() << "\n" << expected.transpose();
}

TEST_F(MultibodyTest, BiasInMotionFollowsLagrangesEquations) {
  // Without gravity, d/dt(M v) − ∂T/∂q = M v̇ + b gives b = Ṁ v − ½ ∂(vᵀ M v)/∂q, Ṁ v along the motion.
  const int n = mb.velocity_count();
  const std::vector<int> dofs = JointDofs();
  auto mass_at = [&](const Eigen::VectorXd& x) { return mb.MassMatrix(Place(model, mb, state, x)); };
  for (int trial = 0; trial < 3; ++trial) {
    const Eigen::VectorXd v = RandomVector(n, &rng);
    mb.SetVelocities(v, &state);
    const Eigen::VectorXd b = mb.BiasForces(state, Vec3::Zero());
    const Eigen::VectorXd mdot_v = (mass_at(kEps * v) - mass_at(-kEps * v)) * v / (2 * kEps);
    const Eigen::VectorXd dT = Gradient(n, [&](const Eigen::VectorXd& x) { return 0.5 * v.dot(mass_at(x) * v); });
    const Eigen::VectorXd expected = (mdot_v - dT)(dofs);
    EXPECT_LE((b(dofs) - expected).norm(), 1e-6 * expected.norm()) << b(dofs).transpose() << "\n"
                                                                    << expected.transpose();

    // The free box: b = (−m g, ω × I_world ω), here with gravity.
    const Eigen::VectorXd bg = mb.BiasForces(state, kGravity);
    const int o = mb.FreeBodyOffset(kBox);
    const Mat3 R = state.body_poses[kBox].orientation.toRotationMatrix();
    const Vec3 w = v.segment<3>(o + 3);
    const Vec3 gyroscopic = w.cross(R * model.bodies[kBox].inertial.inertia * R.transpose() * w);
    EXPECT_LE((bg.segment<3>(o) + 1.5 * kGravity).norm(), 1e-12 * 1.5 * kGravity.norm());
    EXPECT_LE((bg.segment<3>(o + 3) - gyroscopic).norm(), 1e-12 * gyroscopic.norm());
  }
}

TEST_F(MultibodyTest, FreeMotionConservesEnergy) {
  // Classical RK4 on chart coordinates x around the start (q = q0 ⊕ x, see Place), so the scheme is fourth
  // order: ẋ = v except the box's rotation, θ̇ = J_l(θ)⁻¹ ω, and M v̇ = −b. Its own error over 1 s at 1e-4 s
  // is ~1e-14, so any drift measures an inconsistency between M and b.
  const int n = mb.velocity_count(), o = mb.FreeBodyOffset(kBox);
  const SceneState start = state;
  auto at = [&](const Eigen::VectorXd& x, const Eigen::VectorXd& v) {
    SceneState s = Place(model, mb, start, x);
    mb.SetVelocities(v, &s);
    return s;
  };
  auto derivative = [&](const Eigen::VectorXd& x, const Eigen::VectorXd& v) {
    const SceneState s = at(x, v);
    Eigen::VectorXd d(2 * n);
    d.head(n) = v;
    d.segment<3>(o + 3) = LeftJacobian(x.segment<3>(o + 3)).inverse() * v.segment<3>(o + 3);
    d.tail(n) = mb.MassMatrix(s).ldlt().solve(-mb.BiasForces(s, kGravity));
    return d;
  };
  Eigen::VectorXd y = Eigen::VectorXd::Zero(2 * n);
  y.tail(n) = 2 * RandomVector(n, &rng);
  const double h = 1e-4, e0 = mb.Energy(at(y.head(n), y.tail(n)), kGravity);
  double worst = 0;
  for (int step = 1; step <= 10000; ++step) {
    const Eigen::VectorXd k1 = derivative(y.head(n), y.tail(n));
    const Eigen::VectorXd y2 = y + 0.5 * h * k1;
    const Eigen::VectorXd k2 = derivative(y2.head(n), y2.tail(n));
    const Eigen::VectorXd y3 = y + 0.5 * h * k2;
    const Eigen::VectorXd k3 = derivative(y3.head(n), y3.tail(n));
    const Eigen::VectorXd y4 = y + h * k3;
    const Eigen::VectorXd k4 = derivative(y4.head(n), y4.tail(n));
    y += h / 6 * (k1 + 2 * k2 + 2 * k3 + k4);
    if (step % 100 == 0) worst = std::max(worst, std::abs(mb.Energy(at(y.head(n), y.tail(n)), kGravity) / e0 - 1));
  }
  EXPECT_LT(worst, 1e-6);
  // The robot really moved: the check is not vacuous.
  EXPECT_GT(y.head(n)(JointDofs()).cwiseAbs().maxCoeff(), 0.5);
}

TEST(MultibodyPendulumTest, MatchesClosedForm) {
  // A bob l below a horizontal x hinge: M = I_c,xx + m l², b = m g l sin θ (θ about +x lifts the bob toward +y),
  // whatever θ̇ (a single joint has no Coriolis term).
  const double m = 1.2, l = 0.5;
  SceneModel model;
  model.bodies = {Body("p/base", BodyMotion::kArticulated, 1, Vec3::Zero(), Vec3(1, 1, 1), Quat::Identity()),
                  Body("p/bob", BodyMotion::kArticulated, m, Vec3(0, 0, -l), Vec3(0.01, 0.02, 0.015),
                       QuatFromRpy(0.3, 0.4, 0.5))};
  model.joints = {RobotJoint("p/hinge", JointType::kRevolute, "p/base", "p/bob", Pose{}, Vec3::UnitX())};
  model.robots = {RobotSpec{"p", "test", "p/base", {"p/base", "p/bob"}, {"p/hinge"}, {}}};
  model.Reindex();
  SceneState state;
  state.body_poses = {Pose{Vec3(0.3, -0.2, 1), Quat::Identity()}, Pose{}};
  state.body_velocities.resize(2);
  state.joint_velocities = {0};
  const Multibody mb(model);
  ASSERT_EQ(mb.velocity_count(), 1);
  const double pivot_inertia = model.bodies[1].inertial.inertia(0, 0) + m * l * l;
  for (double theta : {-2.5, -1.0, 0.3, 1.2, 2.8}) {
    state.joint_positions = {theta};
    UpdateRobotLinkPoses(model, 0, &state);
    EXPECT_NEAR(mb.MassMatrix(state)(0, 0) / pivot_inertia, 1, 1e-12) << theta;
    const double expected = m * 9.81 * l * std::sin(theta);
    for (double rate : {0.0, 3.0}) {
      mb.SetVelocities(Eigen::VectorXd::Constant(1, rate), &state);
      EXPECT_NEAR(mb.BiasForces(state, kGravity)[0] / expected, 1, 1e-12) << theta << " " << rate;
    }
  }
}

}  // namespace
}  // namespace graspsim
