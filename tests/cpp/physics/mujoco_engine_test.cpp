// The MuJoCo backend (physics/mujoco_engine.cpp) through MakePhysicsEngine, on scenes built in code, against
// closed forms: free fall under both integrators, a box resting on a static box and the contact forces it
// reports, a torque-free tumbling box (centre-of-mass shift and angular velocity frames of the state copy), a
// pendulum's period; and the mapping checked against graspsim's own kinematics (link poses), a mimic joint
// behind a driven leader, divergence and what it refuses.
#include <cmath>
#include <memory>
#include <vector>

#include <gtest/gtest.h>

#include "physics/engine.h"
#include "physics/engine_test_scenes.h"
#include "test_bodies.h"
#include "test_util.h"

namespace graspsim {
namespace {

constexpr double kG = 9.81;

using test_engines::DrivenLink;
using test_engines::GraspsimDrivenLinkAfter;
using test_engines::kDrivenLinkFirstStepVelocity;
using test_engines::kLightInertia;
using test_engines::Link;
using test_engines::Sphere;
using test_engines::World;
using test_objects::RobotJoint;
using test_objects::UniformBox;

// A 1 kg ball 10 m up, no floor, after 1 s of 1 ms steps with `integrator`: how far it fell, its velocity.
struct Fall {
  double fallen = 0, velocity = 0, time = 0;
};
Fall FreeFall(Integrator integrator) {
  World world(PhysicsEngineKind::kMujoco);
  world.model->simulation.integrator = integrator;
  world.Add(Sphere("ball", 0.05, 1.0), Pose{Vec3(0, 0, 10), Quat::Identity()});
  auto engine = world.Start();
  const StepStats stats = engine->Step(&world.state, 1000);
  EXPECT_EQ(stats.awake_bodies, 1u);
  EXPECT_EQ(stats.contacts, 0u);
  EXPECT_EQ(world.state.step, 1000u);
  EXPECT_NEAR(world.state.body_poses[0].position.x(), 0, 1e-12);
  return {10 - world.state.body_poses[0].position.z(), world.state.body_velocities[0].linear.z(), world.state.time};
}

TEST(MujocoEngineTest, FreeFallWithRk4IsExact) {
  // Velocity Verlet maps to MuJoCo's RK4, exact for constant acceleration: the drop g t²/2 and the velocity −g t
  // to rounding (1e-9 relative leaves room for 1000 steps' accumulated rounding, ~1e-13).
  const Fall fall = FreeFall(Integrator::kVelocityVerlet);
  EXPECT_NEAR(fall.time, 1.0, 1e-12);
  EXPECT_NEAR(fall.fallen / (0.5 * kG), 1.0, 1e-9);
  EXPECT_NEAR(fall.velocity / -kG, 1.0, 1e-9);
}

TEST(MujocoEngineTest, FreeFallWithTheDefaultIntegratorIsFirstOrder) {
  // Linearly implicit Euler maps to MuJoCo's "implicit": v += g h, then x += v h, so after n steps the drop is
  // g h² n(n+1)/2, g t²/2 (1 + 1/n): 0.1 % over at 1 ms, within the 0.2 % asked. The error must be there
  // (> 0.05 %), else the default was mapped to RK4.
  const Fall fall = FreeFall(Integrator::kLinearlyImplicitEuler);
  EXPECT_NEAR(fall.fallen / (0.5 * kG), 1.0, 2e-3);
  EXPECT_GT(fall.fallen / (0.5 * kG) - 1, 5e-4);
  EXPECT_NEAR(fall.velocity / -kG, 1.0, 1e-9);  // v = −g h n exactly, to rounding
}

TEST(MujocoEngineTest, BoxRestsOnAStaticBoxAndItsContactsCarryItsWeight) {
  World world(PhysicsEngineKind::kMujoco);
  const size_t floor = world.Add(UniformBox("floor", Vec3(1, 1, 0.1), 1, BodyMotion::kStatic),
                                 Pose{Vec3(0, 0, -0.05), Quat::Identity()});
  const size_t box = world.Add(UniformBox("box", Vec3(0.1, 0.1, 0.1), 0.5), Pose{Vec3(0, 0, 0.05), Quat::Identity()});
  auto engine = world.Start();
  for (int k = 0; k < 20; ++k) {
    engine->Step(&world.state, 100);
    // MuJoCo's soft contacts settle at a small penetration (default solref/solimp), within the 1 mm asked.
    EXPECT_NEAR(world.state.body_poses[box].position.z(), 0.05, 1e-3) << "t = " << world.state.time;
  }
  EXPECT_NEAR(world.state.body_poses[box].position.x(), 0, 1e-6);
  EXPECT_LT(world.state.body_velocities[box].linear.norm(), 1e-3);
  EXPECT_EQ(world.state.body_poses[floor].position, Vec3(0, 0, -0.05));  // static: where it was put
  ASSERT_FALSE(engine->contacts().empty());
  ASSERT_EQ(engine->contacts().size(), engine->contact_forces().size());
  Vec3 on_box = Vec3::Zero();
  for (size_t i = 0; i < engine->contacts().size(); ++i) {
    const ContactPoint& c = engine->contacts()[i];
    ASSERT_TRUE((c.body_a == box && c.body_b == floor) || (c.body_a == floor && c.body_b == box));
    // The normal points out of body_b into body_a: up when body_a is the box.
    EXPECT_NEAR(c.normal.z(), c.body_a == box ? 1 : -1, 1e-6);
    // The force is on body_a: it pushes body_a away from body_b, along the normal.
    EXPECT_GT(engine->contact_forces()[i].dot(c.normal), 0) << "contact " << i;
    on_box += c.body_a == box ? engine->contact_forces()[i] : Vec3(-engine->contact_forces()[i]);
  }
  // At rest the contacts carry the weight; 2 % leaves room for the soft contacts' residual motion.
  EXPECT_GT(on_box.z(), 0) << "the floor pushes the box up";
  EXPECT_NEAR(on_box.z() / (0.5 * kG), 1.0, 2e-2);
  EXPECT_LT(Vec3(on_box.x(), on_box.y(), 0).norm(), 1e-2 * 0.5 * kG);
  ASSERT_EQ(world.state.contacts.size(), engine->contacts().size());
  for (size_t i = 0; i < engine->contacts().size(); ++i) {
    EXPECT_EQ(world.state.contacts[i].force, engine->contact_forces()[i]);
  }
}

TEST(MujocoEngineTest, TumblingBoxWithAnOffsetCentreOfMassKeepsItsMomenta) {
  // No gravity, no contacts: the centre of mass moves in a straight line at constant velocity and the angular
  // momentum about it, L = R I Rᵀ ω (world), is conserved while ω itself precesses (an asymmetric inertia with
  // products). The body's MuJoCo frame sits at the centre of mass and takes its angular velocity in body axes:
  // a wrong shift bends the path by the rotation (the 6 cm offset turns by ~1 rad), a wrong frame for ω turns L
  // by the body's rotation (0.8 rad at the start).
  World world(PhysicsEngineKind::kMujoco);
  world.model->simulation.gravity = Vec3::Zero();
  world.model->simulation.integrator = Integrator::kVelocityVerlet;  // RK4
  BodySpec body = UniformBox("box", Vec3(0.3, 0.2, 0.1), 2.0);
  body.inertial.center_of_mass = Vec3(0.05, -0.03, 0.02);
  body.inertial.inertia << 0.03, 0.004, -0.002, 0.004, 0.025, 0.003, -0.002, 0.003, 0.02;
  const Mat3 inertia = body.inertial.inertia;
  const Vec3 com_local = body.inertial.center_of_mass;
  const Quat start(Eigen::AngleAxisd(0.8, Vec3(1, 2, -1).normalized()));
  const size_t box = world.Add(body, Pose{Vec3(0.2, -0.1, 0.5), start});
  auto engine = world.Start();
  const Vec3 v0(0.3, -0.2, 0.1), w0(1.0, -2.0, 0.5);
  world.state.body_velocities[box] = {v0, w0};
  const Vec3 com0 = world.state.body_poses[box] * com_local;
  auto momentum = [&] {
    const Mat3 R = world.state.body_poses[box].orientation.toRotationMatrix();
    return Vec3(R * inertia * R.transpose() * world.state.body_velocities[box].angular);
  };
  const Vec3 L0 = momentum();
  for (int k = 0; k < 10; ++k) {
    engine->Step(&world.state, 100);  // each call copies the state in and out: ten round trips
    const double t = world.state.time;
    // Straight line to rounding (1e-9 m: RK4 is exact for uniform motion; only the orientation's rounding enters
    // through the centre-of-mass shift, ~1e-16 per step).
    EXPECT_NEAR((world.state.body_poses[box] * com_local - (com0 + v0 * t)).norm(), 0, 1e-9) << "t = " << t;
    EXPECT_NEAR((world.state.body_velocities[box].linear - v0).norm(), 0, 1e-9) << "t = " << t;
    // RK4 at 1 ms with |ω| ~ 2.3 rad/s: its truncation error (~(ω h)⁴ per step) stays far below 1e-6.
    EXPECT_NEAR((momentum() - L0).norm() / L0.norm(), 0, 1e-6) << "t = " << t;
  }
  EXPECT_GT((world.state.body_velocities[box].angular - w0).norm(), 0.05) << "ω precesses: the check has teeth";
  EXPECT_GT(world.state.body_poses[box].orientation.angularDistance(start), 0.5) << "it turned";
}

TEST(MujocoEngineTest, LinkPosesAreMujocosKinematicsAndMatchGraspsims) {
  // A revolute and a prismatic joint with rotated origins, on a rotated base, centres of mass off the joints
  // and products of inertia (MuJoCo's inertial frame differs from the body frame). Nothing moves (no gravity,
  // zero velocities), so after a step the joints are where they were, and the link poses MuJoCo writes back
  // (the state's link poses are wiped first, so they must come from the step) equal graspsim's forward
  // kinematics to rounding (1e-9).
  World world(PhysicsEngineKind::kMujoco);
  world.model->simulation.gravity = Vec3::Zero();
  Mat3 upper_inertia;
  upper_inertia << 0.03, 0.004, -0.002, 0.004, 0.025, 0.003, -0.002, 0.003, 0.02;
  world.Add(Link("arm/base", 3, Vec3::Zero(), Mat3::Identity() * 0.01),
            Pose{Vec3(0.1, -0.2, 1.5), Quat(Eigen::AngleAxisd(0.4, Vec3(1, -2, 0.5).normalized()))});
  world.Add(Link("arm/upper", 2, Vec3(0.15, 0.05, -0.02), upper_inertia), Pose());
  world.Add(Link("arm/slider", 0.8, Vec3(0.01, 0.02, 0.1), Mat3(Vec3(0.004, 0.002, 0.003).asDiagonal())), Pose());
  world.model->joints.push_back(
      RobotJoint("arm/shoulder", JointType::kRevolute, "arm/base", "arm/upper",
                 Pose{Vec3(0.05, -0.02, 0.1), Quat(Eigen::AngleAxisd(0.7, Vec3(0.3, 1, 0).normalized()))},
                 Vec3(0.2, 1, 0.3)));
  world.model->joints.push_back(RobotJoint("arm/slide", JointType::kPrismatic, "arm/upper", "arm/slider",
                                           Pose{Vec3(0.3, 0.1, -0.05), Quat(Eigen::AngleAxisd(-0.5, Vec3::UnitZ()))},
                                           Vec3(1, 0.5, -0.2)));
  world.AddRobot("arm", 0, 0);
  world.state.joint_positions = {0.6, 0.07};
  auto engine = world.Start();
  const SceneState expected = world.state;  // links placed by UpdateRobotLinkPoses (World::Start)
  world.state.body_poses[1] = world.state.body_poses[2] = Pose();
  engine->Step(&world.state, 1);
  EXPECT_NEAR(world.state.joint_positions[0], 0.6, 1e-12);
  EXPECT_NEAR(world.state.joint_positions[1], 0.07, 1e-12);
  for (size_t i = 0; i < world.model->bodies.size(); ++i) {
    EXPECT_NEAR((world.state.body_poses[i].position - expected.body_poses[i].position).norm(), 0, 1e-9)
        << world.model->bodies[i].id;
    EXPECT_NEAR(world.state.body_poses[i].orientation.angularDistance(expected.body_poses[i].orientation), 0, 1e-9)
        << world.model->bodies[i].id;
  }
  EXPECT_GT((expected.body_poses[2].position - expected.body_poses[0].position).norm(), 0.2) << "not trivial";
}

TEST(MujocoEngineTest, PendulumPeriodMatchesTheClosedForm) {
  // A 1 kg bob (sphere inertia, r = 2 cm) 1 m below a y hinge, released at 0.3 rad, RK4 at 1 ms:
  // T = 4 √(I / (m g L)) K(sin(θ0/2)), I = I_c + m L², from the interpolated θ = 0 crossings over 10 s. RK4's
  // error in the period is ~(ω h)⁴ ~ 1e-10 and the crossings' linear interpolation errs by well under 1e-6 s
  // (θ'' ~ 0 at a crossing), so 1e-4 relative is a loose bound that still catches a wrong inertia or lever arm
  // (2e-4 of I, 1e-4 of L).
  const double m = 1, length = 1, radius = 0.02, theta0 = 0.3;
  World world(PhysicsEngineKind::kMujoco);
  world.model->simulation.integrator = Integrator::kVelocityVerlet;
  world.Add(Link("p/base", 1, Vec3::Zero(), Mat3::Identity() * 1e-3), Pose{Vec3(0, 0, 3), Quat::Identity()});
  world.Add(Link("p/bob", m, Vec3(0, 0, -length), Mat3::Identity() * 0.4 * m * radius * radius), Pose());
  world.model->joints.push_back(RobotJoint("p/hinge", JointType::kRevolute, "p/base", "p/bob", Pose(), Vec3::UnitY()));
  world.AddRobot("p", 0, 0);
  world.state.joint_positions = {theta0};
  auto engine = world.Start();
  std::vector<double> crossings;
  double previous = world.state.joint_positions[0], t_previous = 0, largest = 0;
  for (int k = 0; k < 10000; ++k) {
    engine->Step(&world.state, 1);
    const double theta = world.state.joint_positions[0];
    largest = std::max(largest, std::abs(theta));
    if ((previous > 0) != (theta > 0)) {
      crossings.push_back(t_previous - previous * (world.state.time - t_previous) / (theta - previous));
    }
    previous = theta;
    t_previous = world.state.time;
  }
  ASSERT_GE(crossings.size(), 8u);
  const double period = 2 * (crossings.back() - crossings.front()) / (crossings.size() - 1);
  const double inertia = 0.4 * m * radius * radius + m * length * length;
  const double expected = 4 * std::sqrt(inertia / (m * kG * length)) * std::comp_ellint_1(std::sin(theta0 / 2));
  EXPECT_NEAR(period / expected, 1.0, 1e-4);
  EXPECT_NEAR(largest, theta0, 1e-4) << "no energy lost or gained";
  // The bob's link frame stays at the hinge, turned by θ about y.
  const Pose& bob = world.state.body_poses[1];
  EXPECT_NEAR((bob.position - Vec3(0, 0, 3)).norm(), 0, 1e-9);
  EXPECT_NEAR(bob.orientation.angularDistance(Quat(Eigen::AngleAxisd(world.state.joint_positions[0], Vec3::UnitY()))),
              0, 1e-9);
}

TEST(MujocoEngineTest, StiffDriveGoesThroughTheImplicitDamping) {
  // h |D| / I ≈ 460: an explicit step of this drive diverges at once; through MuJoCo's implicit integrator (the
  // drive's damping as joint damping) the first step is implicit Euler's v1 = h f0 / (I − h D) = 0.45397 rad/s
  // (1e-9: rounding), and after 0.5 s the PI loop has brought it to 0.5 rad/s (its integral removes the rest
  // with a time constant ~0.1 s: ~4e-4 rad/s left, so 1e-3).
  World world = DrivenLink(PhysicsEngineKind::kMujoco, Integrator::kLinearlyImplicitEuler);
  auto engine = world.Start();
  engine->Step(&world.state, 1);
  EXPECT_NEAR(world.state.joint_velocities[0], kDrivenLinkFirstStepVelocity, 1e-9);
  engine->Step(&world.state, 499);
  EXPECT_NEAR(world.state.joint_velocities[0], 0.5, 1e-3);
  // graspsim's own engine runs the same motor model through the same implicit Euler step: one hinge, no
  // gravity torque, no Coriolis terms, so both agree to rounding (1e-9).
  const SceneState reference = GraspsimDrivenLinkAfter(500);
  EXPECT_NEAR(world.state.joint_velocities[0], reference.joint_velocities[0], 1e-9);
  EXPECT_NEAR(world.state.joint_positions[0], reference.joint_positions[0], 1e-9);
}

TEST(MujocoEngineTest, DriveReportsTheForceTheStepApplied) {
  // The force a drive reports is the one the step applied (physics/current_limit_test.cpp, graspsim's engine):
  // f0 + D (v1 − v0), which here is what accelerated the link, I v1 / h (1e-6 N m: rounding of v1 / h).
  World world = DrivenLink(PhysicsEngineKind::kMujoco, Integrator::kLinearlyImplicitEuler);
  auto engine = world.Start();
  engine->Step(&world.state, 1);
  EXPECT_NEAR(world.state.actuators.at(0).joint_force, kLightInertia * world.state.joint_velocities[0] / 1e-3, 1e-6);
}

TEST(MujocoEngineTest, DriveSwitchedOffLeavesTheJointFree) {
  // Switching a drive off (SetActuators with ACTUATOR_MODE_OFF erases it from state.actuators,
  // rpc/simulation_service.cpp) leaves the joint free: nothing acts on the hinge, so the velocity it is given
  // stays (1e-9: rounding). Measured before the skip: −0.5 rad/s became +0.49 rad/s within 0.1 s, the stale
  // drive pulling it back to its last set-point.
  World world = DrivenLink(PhysicsEngineKind::kMujoco, Integrator::kLinearlyImplicitEuler);
  auto engine = world.Start();
  engine->Step(&world.state, 200);
  ASSERT_NEAR(world.state.joint_velocities[0], 0.5, 0.05);
  world.state.actuators.clear();
  world.state.joint_velocities[0] = -0.5;
  engine->Step(&world.state, 100);
  EXPECT_NEAR(world.state.joint_velocities[0], -0.5, 1e-9);
}

TEST(MujocoEngineTest, StiffDriveUnderRk4) {
  // The same drive with the velocity Verlet integrator: graspsim's engine runs it (0.4995 rad/s after 0.5 s);
  // MuJoCo's RK4 takes joint damping explicitly (h |D| / I ≈ 460 ≫ 2.8, its stability bound). 1e-3 as in
  // StiffDriveGoesThroughTheImplicitDamping.
  World world = DrivenLink(PhysicsEngineKind::kMujoco, Integrator::kVelocityVerlet);
  auto engine = world.Start();
  engine->Step(&world.state, 500);
  EXPECT_NEAR(world.state.joint_velocities[0], 0.5, 1e-3);
}

// A robot of two hinges about z on one base, the second mimicking the first (follower = 2 leader + 0.1: not
// symmetric in the two, so swapped roles would show), its leader driven at 0.5 rad/s by the default drive
// (physics/actuators.h). Links of `mass` kg with their centre of mass `arm` m beside the axis (no gravity torque)
// and inertia `inertia` about it.
World MimicPair(double mass, double arm, double inertia) {
  World world(PhysicsEngineKind::kMujoco);
  world.Add(Link("g/base", 1, Vec3::Zero(), Mat3::Identity() * 1e-3), Pose{Vec3(0, 0, 1), Quat::Identity()});
  world.Add(Link("g/leader", mass, Vec3(arm, 0, 0), Mat3::Identity() * inertia), Pose());
  world.Add(Link("g/follower", mass, Vec3(arm, 0, 0), Mat3::Identity() * inertia), Pose());
  world.model->joints.push_back(RobotJoint("g/leader", JointType::kRevolute, "g/base", "g/leader",
                                           Pose{Vec3(0, 0.1, 0), Quat::Identity()}, Vec3::UnitZ()));
  world.model->joints.push_back(RobotJoint("g/follower", JointType::kRevolute, "g/base", "g/follower",
                                           Pose{Vec3(0, -0.1, 0), Quat::Identity()}, Vec3::UnitZ(),
                                           MimicSpec{"g/leader", 2, 0.1}));
  world.AddRobot("g", 0, 0);
  world.state.joint_positions = {0, 0.1};
  world.state.actuators[0].command = {ActuatorMode::kVelocity, 0.5, -1};
  return world;
}

TEST(MujocoEngineTest, MimicJointFollowsItsDrivenLeader) {
  // 0.1 kg m² links about their hinges: the drive starts at its 25 N m current limit (the leader and, through
  // the equality constraint, the follower accelerate for ~10 ms), then its PI loop holds 0.5 rad/s through the
  // implicit damping; the velocity error left after 0.5 s is ~5e-4 rad/s (integral time constant ~0.1 s), so
  // 2e-3, the follower's twice that. MuJoCo's equality constraint is soft (default solref: 20 ms): it lags
  // while the pair accelerates (measured 1.8e-3 rad at 38 ms, so 5e-3), then closes to ~1e-5 rad.
  World world = MimicPair(1, 0.1, 0.09);
  auto engine = world.Start();
  double worst = 0;
  for (int k = 0; k < 500; ++k) {
    engine->Step(&world.state, 1);
    worst = std::max(worst, std::abs(world.state.joint_positions[1] - (2 * world.state.joint_positions[0] + 0.1)));
  }
  EXPECT_NEAR(world.state.time, 0.5, 1e-12);
  EXPECT_LT(worst, 5e-3);
  EXPECT_NEAR(world.state.joint_positions[1], 2 * world.state.joint_positions[0] + 0.1, 1e-3);
  EXPECT_NEAR(world.state.joint_velocities[0], 0.5, 2e-3);
  EXPECT_NEAR(world.state.joint_velocities[1], 1.0, 4e-3);
  // It turned about 0.5 rad/s × 0.5 s, less the loop's settling (~0.01 rad).
  EXPECT_GT(world.state.joint_positions[0], 0.22);
  EXPECT_LT(world.state.joint_positions[0], 0.25);
}

TEST(MujocoEngineTest, MimicJointFollowsAStifflyDrivenLightLeader) {
  // The pair with light links (6e-4 kg m² about the hinges) and the linear stiff drive of DrivenLink: graspsim's
  // engine keeps the pair together exactly (its mimic joint is a reduced coordinate) and brings the leader to
  // 0.4500 rad/s in the first step. MuJoCo's equality constraint is soft (default solref, 0.02 s): the follower
  // lags while the pair accelerates, by 1.3 mrad at most here; with the drive's damping as a joint damping the
  // constraint solver did not see it and the pair drifted 3.4 rad apart (the drive is an armature now).
  World world = MimicPair(0.2, 0.05, 1e-4);
  JointActuator& drive = world.state.actuators[0];
  drive.motor.current_limit = 100;
  drive.motor.voltage_limit = 48;
  auto engine = world.Start();
  double worst = 0;
  for (int k = 0; k < 500; ++k) {
    engine->Step(&world.state, 1);
    worst = std::max(worst, std::abs(world.state.joint_positions[1] - (2 * world.state.joint_positions[0] + 0.1)));
  }
  EXPECT_LT(worst, 2e-3);
  EXPECT_NEAR(world.state.joint_velocities[1], 1.0, 4e-3);
}

TEST(MujocoEngineTest, AFullContactListStopsTheStepInsteadOfDroppingContacts) {
  // 12 boxes piled into one place: 66 overlapping pairs of up to 8 contacts each, more than the list sized from
  // 12 geometries (100 + 8 × 12 = 196). The step refuses, names the limit and leaves the state as it was; one box
  // alone steps.
  World world(PhysicsEngineKind::kMujoco);
  for (int i = 0; i < 12; ++i) {
    world.Add(test_objects::UniformBox("box" + std::to_string(i), Vec3(0.1, 0.1, 0.1), 1.0),
              Pose{Vec3(0, 0, 1), Quat::Identity()});
  }
  auto engine = world.Start();
  const SceneState before = world.state;
  test_util::ExpectError([&] { engine->Step(&world.state, 1); }, ErrorCode::kFailedPrecondition,
                         {"engine mujoco", "more contacts than the backend's 196", "Use the graspsim engine"});
  EXPECT_EQ(world.state.step, before.step);
  EXPECT_EQ(world.state.body_poses[0].position, before.body_poses[0].position);

  World alone(PhysicsEngineKind::kMujoco);
  alone.Add(test_objects::UniformBox("box", Vec3(0.1, 0.1, 0.1), 1.0), Pose{Vec3(0, 0, 1), Quat::Identity()});
  auto single = alone.Start();
  single->Step(&alone.state, 10);
  EXPECT_EQ(alone.state.step, 10u);
}

TEST(MujocoEngineTest, DivergenceIsReportedAndLeavesTheStateAsItWas) {
  // 1e4 m/s is past the default divergence speed (1e3 m/s): the step refuses and restores the state.
  World world(PhysicsEngineKind::kMujoco);
  world.Add(Sphere("ball", 0.05, 1.0), Pose{Vec3(0, 0, 10), Quat::Identity()});
  auto engine = world.Start();
  engine->Step(&world.state, 5);
  world.state.body_velocities[0].linear = Vec3(1e4, 0, 0);
  const SceneState before = world.state;
  test_util::ExpectError([&] { engine->Step(&world.state, 10); }, ErrorCode::kFailedPrecondition,
                         {"simulation (engine mujoco) diverged", "'ball'"});
  EXPECT_EQ(world.state.step, before.step);
  EXPECT_EQ(world.state.time, before.time);
  EXPECT_EQ(world.state.body_poses[0].position, before.body_poses[0].position);
  EXPECT_EQ(world.state.body_poses[0].orientation.coeffs(), before.body_poses[0].orientation.coeffs());
  EXPECT_EQ(world.state.body_velocities[0].linear, before.body_velocities[0].linear);
  EXPECT_EQ(world.state.body_velocities[0].angular, before.body_velocities[0].angular);
  // And it steps on from there once the state is sane again.
  world.state.body_velocities[0].linear = Vec3::Zero();
  engine->Step(&world.state, 10);
  EXPECT_EQ(world.state.step, before.step + 10);
  EXPECT_LT(world.state.body_poses[0].position.z(), 10);
}

TEST(MujocoEngineTest, DivergenceIsFoundAtTheStepItHappens) {
  // As on graspsim's engine and Bullet (bullet_engine_test.cpp): every step is checked. A ball dropped 10 cm
  // onto a floor with divergence_speed 1 m/s passes 1 m/s at step 102 (v = g h n, first order), lands at
  // ~1.4 m/s and comes to rest: a 1000-step call must fail there, not return the ball at rest.
  World world(PhysicsEngineKind::kMujoco);
  world.model->simulation.divergence_speed = 1;
  world.Add(UniformBox("floor", Vec3(1, 1, 0.1), 1, BodyMotion::kStatic), Pose{Vec3(0, 0, -0.05), Quat::Identity()});
  world.Add(Sphere("ball", 0.05, 1.0), Pose{Vec3(0, 0, 0.15), Quat::Identity()});
  auto engine = world.Start();
  test_util::ExpectError([&] { engine->Step(&world.state, 1000); }, ErrorCode::kFailedPrecondition,
                         {"simulation (engine mujoco) diverged at step 102", "'ball'"});
  EXPECT_EQ(world.state.step, 0u);
}

TEST(MujocoEngineTest, CurvedTactilePadsAreRefused) {
  World world(PhysicsEngineKind::kMujoco);
  world.Add(Link("p/base", 1, Vec3::Zero(), Mat3::Identity() * 1e-3), Pose());
  world.AddRobot("p", 0, 0);
  TactileArraySpec pad;
  pad.id = "p/pad";
  pad.body_id = "p/base";
  pad.bend_radius_x = 0.02;
  world.model->tactile_arrays.push_back(pad);
  world.model->Reindex();
  test_util::ExpectError([&] { MakePhysicsEngine(world.model); }, ErrorCode::kFailedPrecondition,
                         {"engine: mujoco does not simulate curved tactile pads", "'p/pad'", "bend_radius 0.02 0"});
}

}  // namespace
}  // namespace graspsim
