// The Bullet backend (physics/bullet_engine.cpp) through MakePhysicsEngine, on scenes built in code, against
// closed forms: free fall, a box resting on a static box, a pendulum's period; and the mapping checked against
// graspsim's own kinematics and dynamics (link poses, an arm with rotated frames and products of inertia), mimic
// joints, divergence and what it refuses.
#include <cmath>
#include <memory>

#include <gtest/gtest.h>

#include "physics/engine.h"
#include "physics/engine_test_scenes.h"
#include "physics/simulation.h"
#include "test_bodies.h"
#include "test_util.h"

namespace graspsim {
namespace {

constexpr double kG = 9.81;

using test_objects::RobotJoint;
using test_objects::UniformBox;
using test_engines::DrivenLink;
using test_engines::GraspsimDrivenLinkAfter;
using test_engines::kDrivenLinkFirstStepVelocity;
using test_engines::kLightInertia;
using test_engines::Link;
using test_engines::MeshBody;
using test_engines::Sphere;
using test_engines::World;

TEST(BulletEngineTest, FreeFallIsSemiImplicitEuler) {
  // Bullet's one integrator: v += g h, then x += v h, so z_n = z0 − g h² n(n+1)/2 to rounding, and after 1 s the
  // drop is g t²/2 to within g h t/2 (0.1 % at 1 ms).
  World world(PhysicsEngineKind::kBullet);
  world.model->simulation.integrator = Integrator::kVelocityVerlet;  // ignored: Bullet has one integrator
  world.Add(Sphere("ball", 0.05, 1.0), Pose{Vec3(0, 0, 10), Quat::Identity()});
  auto engine = world.Start();
  const StepStats stats = engine->Step(&world.state, 1000);
  const double fallen = 10 - world.state.body_poses[0].position.z();
  EXPECT_NEAR(fallen, kG * 1e-6 * 1000 * 1001 / 2, 1e-9);
  EXPECT_NEAR(fallen / (0.5 * kG), 1.0, 1.1e-3);
  EXPECT_NEAR(world.state.body_velocities[0].linear.z(), -kG, 1e-9);
  EXPECT_NEAR(world.state.time, 1.0, 1e-12);
  EXPECT_EQ(world.state.step, 1000u);
  EXPECT_EQ(stats.awake_bodies, 1u);
  EXPECT_EQ(stats.contacts, 0u);
}

TEST(BulletEngineTest, BoxRestsOnAStaticBoxAndItsContactsCarryItsWeight) {
  World world(PhysicsEngineKind::kBullet);
  const size_t floor = world.Add(UniformBox("floor", Vec3(1, 1, 0.1), 1, BodyMotion::kStatic),
                                 Pose{Vec3(0, 0, -0.05), Quat::Identity()});
  const size_t box = world.Add(UniformBox("box", Vec3(0.1, 0.1, 0.1), 0.5), Pose{Vec3(0, 0, 0.05), Quat::Identity()});
  auto engine = world.Start();
  for (int k = 0; k < 20; ++k) {
    engine->Step(&world.state, 100);
    EXPECT_NEAR(world.state.body_poses[box].position.z(), 0.05, 1e-3) << "t = " << world.state.time;
  }
  EXPECT_NEAR(world.state.body_poses[box].position.x(), 0, 1e-6);
  EXPECT_LT(world.state.body_velocities[box].linear.norm(), 1e-3);
  EXPECT_NEAR(world.state.body_poses[floor].position.z(), -0.05, 0);  // static: where it was put
  // The force the floor exerts on the box, from either side of each contact point.
  ASSERT_FALSE(engine->contacts().empty());
  ASSERT_EQ(engine->contacts().size(), engine->contact_forces().size());
  Vec3 on_box = Vec3::Zero();
  for (size_t i = 0; i < engine->contacts().size(); ++i) {
    const ContactPoint& c = engine->contacts()[i];
    ASSERT_TRUE((c.body_a == box && c.body_b == floor) || (c.body_a == floor && c.body_b == box));
    // The normal points out of body_b into body_a.
    EXPECT_NEAR(c.normal.z(), c.body_a == box ? 1 : -1, 1e-6);
    on_box += c.body_a == box ? engine->contact_forces()[i] : Vec3(-engine->contact_forces()[i]);
  }
  EXPECT_NEAR(on_box.z() / (0.5 * kG), 1.0, 1e-3);
  EXPECT_LT(Vec3(on_box.x(), on_box.y(), 0).norm(), 1e-3);
  EXPECT_EQ(world.state.contacts.size(), engine->contacts().size());
}

TEST(BulletEngineTest, MeshBoxRestsOnAStaticMeshSlab) {
  // A moving mesh collides as its convex hull (grown by its 0.1 mm margin), a static one as its triangles: placed
  // on the slab, the box stays put.
  World world(PhysicsEngineKind::kBullet);
  world.Add(MeshBody(UniformBox("slab", Vec3(2, 2, 0.2), 1, BodyMotion::kStatic)),
            Pose{Vec3(0, 0, -0.1), Quat::Identity()});
  const size_t box = world.Add(MeshBody(UniformBox("box", Vec3(0.1, 0.06, 0.04), 0.3)),
                               Pose{Vec3(0.3, -0.2, 0.0201), Quat(Eigen::AngleAxisd(0.5, Vec3::UnitZ()))});
  auto engine = world.Start();
  engine->Step(&world.state, 1000);
  EXPECT_NEAR(world.state.body_poses[box].position.z(), 0.0201, 1e-4);
  EXPECT_NEAR((world.state.body_poses[box].position.head<2>() - Eigen::Vector2d(0.3, -0.2)).norm(), 0, 1e-4);
  EXPECT_NEAR(world.state.body_poses[box].orientation.angularDistance(Quat(Eigen::AngleAxisd(0.5, Vec3::UnitZ()))), 0,
              1e-4);
  EXPECT_LT(world.state.body_velocities[box].linear.norm(), 1e-3);
  EXPECT_FALSE(engine->contacts().empty());
}

TEST(BulletEngineTest, RobotLinksCollideWithStaticObjects) {
  // A 40 cm bar on a y hinge 10 cm above a static floor, released level: it swings down until its far lower edge
  // lands on the floor and stays there.
  World world(PhysicsEngineKind::kBullet);
  world.Add(UniformBox("floor", Vec3(2, 2, 0.1), 1, BodyMotion::kStatic), Pose{Vec3(0, 0, -0.05), Quat::Identity()});
  const size_t base = world.Add(Link("arm/base", 1, Vec3::Zero(), Mat3::Identity() * 1e-3),
                                Pose{Vec3(0, 0, 0.1), Quat::Identity()});
  BodySpec bar = UniformBox("arm/bar", Vec3(0.4, 0.02, 0.02), 0.5, BodyMotion::kArticulated);
  bar.robot_id = "arm";
  bar.collision[0].origin.position = Vec3(0.2, 0, 0);
  bar.inertial.center_of_mass = Vec3(0.2, 0, 0);
  const size_t link = world.Add(bar, Pose());
  world.model->joints.push_back(RobotJoint("arm/hinge", JointType::kRevolute, "arm/base", "arm/bar", Pose(),
                                           Vec3::UnitY()));
  world.AddRobot("arm", base, 0);
  auto engine = world.Start();
  engine->Step(&world.state, 1000);
  const double theta = world.state.joint_positions[0];
  EXPECT_GT(theta, 0.1) << "it fell";
  // The far lower edge (x = 0.4, z = −0.01 in the bar's frame) on the floor.
  const Vec3 edge = world.state.body_poses[link] * Vec3(0.4, 0, -0.01);
  EXPECT_NEAR(edge.z(), 0, 1e-3);
  EXPECT_LT(std::abs(world.state.joint_velocities[0]), 1e-2);
  bool touching = false;
  for (const ContactPoint& c : engine->contacts()) touching |= (c.body_a == link || c.body_b == link);
  EXPECT_TRUE(touching);
}

TEST(BulletEngineTest, PendulumPeriodMatchesTheClosedForm) {
  // A 1 kg bob (sphere inertia, r = 2 cm) 1 m below a y hinge, released at 60°: T = 4 √(I / (m g L)) K(sin 30°),
  // I = I_c + m L², from the θ = 0 crossings over 10 s (interpolated).
  const double m = 1, length = 1, radius = 0.02, theta0 = M_PI / 3;
  World world(PhysicsEngineKind::kBullet);
  world.Add(Link("p/base", 1, Vec3::Zero(), Mat3::Identity() * 1e-3), Pose{Vec3(0, 0, 3), Quat::Identity()});
  world.Add(Link("p/bob", m, Vec3(0, 0, -length), Mat3::Identity() * 0.4 * m * radius * radius), Pose());
  world.model->joints.push_back(RobotJoint("p/hinge", JointType::kRevolute, "p/base", "p/bob", Pose(), Vec3::UnitY()));
  world.AddRobot("p", 0, 0);
  world.state.joint_positions = {theta0};
  auto engine = world.Start();
  std::vector<double> crossings;
  double previous = world.state.joint_positions[0], t_previous = 0;
  for (int k = 0; k < 10000; ++k) {
    engine->Step(&world.state, 1);
    const double theta = world.state.joint_positions[0];
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
  EXPECT_NEAR(period / expected, 1.0, 1e-3);
  // The bob's link frame stays at the hinge, turned by θ about y.
  const Pose& bob = world.state.body_poses[1];
  EXPECT_NEAR((bob.position - Vec3(0, 0, 3)).norm(), 0, 1e-9);
  EXPECT_NEAR(bob.orientation.angularDistance(Quat(Eigen::AngleAxisd(world.state.joint_positions[0], Vec3::UnitY()))),
              0, 1e-9);
}

// An arm with rotated joint frames, centres of mass off the joints and products of inertia (so each link's Bullet
// frame is turned onto its principal axes): a revolute shoulder, a prismatic slide, a fixed flange, a continuous
// wrist, on a rotated base.
World Arm(PhysicsEngineKind engine) {
  World world(engine);
  Mat3 upper_inertia, hand_inertia;
  upper_inertia << 0.03, 0.004, -0.002, 0.004, 0.02, 0.003, -0.002, 0.003, 0.01;
  hand_inertia << 0.004, -0.0005, 0.0008, -0.0005, 0.003, 0.0002, 0.0008, 0.0002, 0.002;
  const Quat base_rotation(Eigen::AngleAxisd(0.4, Vec3(1, -2, 0.5).normalized()));
  world.Add(Link("arm/base", 3, Vec3::Zero(), Mat3::Identity() * 0.01), Pose{Vec3(0.1, -0.2, 1.5), base_rotation});
  world.Add(Link("arm/upper", 2, Vec3(0.15, 0.05, -0.02), upper_inertia), Pose());
  world.Add(Link("arm/slider", 0.8, Vec3(0.01, 0.02, 0.1), Mat3(Vec3(0.004, 0.002, 0.003).asDiagonal())), Pose());
  world.Add(Link("arm/flange", 0.3, Vec3(0, 0, 0.02), Mat3::Identity() * 1e-4), Pose());
  world.Add(Link("arm/hand", 0.7, Vec3(0.02, -0.03, 0.08), hand_inertia), Pose());
  auto& joints = world.model->joints;
  joints.push_back(RobotJoint("arm/shoulder", JointType::kRevolute, "arm/base", "arm/upper",
                              Pose{Vec3(0.05, -0.02, 0.1), Quat(Eigen::AngleAxisd(0.7, Vec3(0.3, 1, 0).normalized()))},
                              Vec3(0.2, 1, 0.3)));
  joints.push_back(RobotJoint("arm/slide", JointType::kPrismatic, "arm/upper", "arm/slider",
                              Pose{Vec3(0.3, 0.1, -0.05), Quat(Eigen::AngleAxisd(-0.5, Vec3::UnitZ()))},
                              Vec3(1, 0.5, -0.2)));
  joints.push_back(RobotJoint("arm/flange", JointType::kFixed, "arm/slider", "arm/flange",
                              Pose{Vec3(0, 0.02, 0.2), Quat(Eigen::AngleAxisd(-1.1, Vec3(1, 0.2, 0.7).normalized()))},
                              Vec3::UnitX()));
  joints.push_back(RobotJoint("arm/wrist", JointType::kContinuous, "arm/flange", "arm/hand",
                              Pose{Vec3(0.01, 0, 0.05), Quat(Eigen::AngleAxisd(0.3, Vec3::UnitX()))},
                              Vec3(0, 0.3, 1)));
  world.AddRobot("arm", 0, 0);
  world.state.joint_positions = {0.3, 0.05, 0, -0.4};
  world.model->simulation.time_step = 1e-4;
  world.model->simulation.integrator = Integrator::kSemiImplicitEuler;
  return world;
}

TEST(BulletEngineTest, LinkPosesFollowTheJointsAsGraspsimsKinematicsPlaceThem) {
  World world = Arm(PhysicsEngineKind::kBullet);
  auto engine = world.Start();
  engine->Step(&world.state, 2000);
  EXPECT_GT(std::abs(world.state.joint_velocities[0]), 0.1) << "it moves";
  SceneState expected = world.state;
  UpdateRobotLinkPoses(*world.model, 0, &expected);
  for (size_t i = 1; i < world.model->bodies.size(); ++i) {
    EXPECT_NEAR((world.state.body_poses[i].position - expected.body_poses[i].position).norm(), 0, 1e-9)
        << world.model->bodies[i].id;
    EXPECT_NEAR(world.state.body_poses[i].orientation.angularDistance(expected.body_poses[i].orientation), 0, 1e-9)
        << world.model->bodies[i].id;
  }
  EXPECT_EQ(world.state.joint_positions[2], 0);  // the fixed joint
}

TEST(BulletEngineTest, ArmMovesAsOnGraspsimsEngine) {
  // The same arm under gravity on both engines at 0.1 ms for 0.3 s. Both are Featherstone multibodies in reduced
  // coordinates stepped by semi-implicit Euler, so with the frames mapped right they agree to rounding (measured:
  // 5e-15 rad); any error in the mapping (frames, axes, centres of mass, principal axes) shows at once.
  World bullet = Arm(PhysicsEngineKind::kBullet);
  World graspsim = Arm(PhysicsEngineKind::kGraspsim);
  auto a = bullet.Start();
  auto b = graspsim.Start();
  for (int k = 0; k < 30; ++k) {
    a->Step(&bullet.state, 100);
    b->Step(&graspsim.state, 100);
    for (size_t j : {0, 1, 3}) {
      EXPECT_NEAR(bullet.state.joint_positions[j], graspsim.state.joint_positions[j], 1e-9)
          << bullet.model->joints[j].id << " at t = " << bullet.state.time;
      EXPECT_NEAR(bullet.state.joint_velocities[j], graspsim.state.joint_velocities[j], 1e-7)
          << bullet.model->joints[j].id << " at t = " << bullet.state.time;
    }
  }
  EXPECT_GT(std::abs(graspsim.state.joint_positions[0] - 0.3), 0.05) << "it moved";
}

TEST(BulletEngineTest, MimicJointFollowsItsLeader) {
  // Two fingers on vertical slides, the second mimicking the first (−1, offset 1 cm); gravity pulls both down,
  // so the pair can only move by the first going down while the second goes up: it stays in balance — and an
  // initial velocity of the leader carries the follower along mirrored.
  World world(PhysicsEngineKind::kBullet);
  world.model->simulation.gravity = Vec3(0, 0, -kG);
  world.Add(Link("g/base", 1, Vec3::Zero(), Mat3::Identity() * 1e-3), Pose{Vec3(0, 0, 1), Quat::Identity()});
  world.Add(Link("g/left", 0.1, Vec3::Zero(), Mat3::Identity() * 1e-5), Pose());
  world.Add(Link("g/right", 0.1, Vec3::Zero(), Mat3::Identity() * 1e-5), Pose());
  world.model->joints.push_back(RobotJoint("g/left", JointType::kPrismatic, "g/base", "g/left",
                                           Pose{Vec3(0, 0.05, 0), Quat::Identity()}, Vec3::UnitZ()));
  world.model->joints.push_back(RobotJoint("g/right", JointType::kPrismatic, "g/base", "g/right",
                                           Pose{Vec3(0, -0.05, 0), Quat::Identity()}, Vec3::UnitZ(),
                                           MimicSpec{"g/left", -1, 0.01}));
  world.AddRobot("g", 0, 0);
  world.state.joint_positions = {0, 0.01};
  auto engine = world.Start();
  world.state.joint_velocities = {0.1, -0.1};
  for (int k = 0; k < 10; ++k) {
    engine->Step(&world.state, 100);
    EXPECT_NEAR(world.state.joint_positions[1], -world.state.joint_positions[0] + 0.01, 1e-4)
        << "t = " << world.state.time;
  }
  EXPECT_NEAR(world.state.joint_positions[0], 0.1, 0.01) << "the leader kept its speed: gravity cancels";
}

TEST(BulletEngineTest, StiffDriveIsImplicitThroughItsSoftVelocityRow) {
  // h |D| / I ≈ 460 (engine_test_scenes.h's DrivenLink): an explicit step of this drive diverges at once. As a
  // soft velocity row in Bullet's solver (DriveDamper) the first step is implicit Euler's
  // v1 = h f0 / (I − h D) = 0.45397 rad/s (1e-9: rounding), its reported force is what accelerated the link,
  // I v1 / h, and after 0.5 s the PI loop has brought it to 0.5 rad/s as on graspsim's engine (same motor, same
  // implicit step; 1e-6: Bullet's solver stops at its tolerance).
  World world = DrivenLink(PhysicsEngineKind::kBullet, Integrator::kLinearlyImplicitEuler);
  auto engine = world.Start();
  engine->Step(&world.state, 1);
  EXPECT_NEAR(world.state.joint_velocities[0], kDrivenLinkFirstStepVelocity, 1e-9);
  EXPECT_NEAR(world.state.actuators.at(0).joint_force, kLightInertia * world.state.joint_velocities[0] / 1e-3, 1e-6);
  engine->Step(&world.state, 499);
  EXPECT_NEAR(world.state.joint_velocities[0], 0.5, 1e-3);
  EXPECT_NEAR(world.state.joint_velocities[0], GraspsimDrivenLinkAfter(500).joint_velocities[0], 1e-6);
}

TEST(BulletEngineTest, DivergenceIsReportedAndLeavesTheStateAsItWas) {
  World world(PhysicsEngineKind::kBullet);
  world.model->simulation.divergence_speed = 1;  // m/s: a fall of 0.11 s exceeds it
  world.Add(Sphere("ball", 0.05, 1.0), Pose{Vec3(0, 0, 10), Quat::Identity()});
  auto engine = world.Start();
  engine->Step(&world.state, 50);
  const SceneState before = world.state;
  test_util::ExpectError([&] { engine->Step(&world.state, 100); }, ErrorCode::kFailedPrecondition,
                         {"simulation (engine bullet) diverged at step 102", "'ball'"});
  EXPECT_EQ(world.state.step, before.step);
  EXPECT_EQ(world.state.body_poses[0].position, before.body_poses[0].position);
  EXPECT_EQ(world.state.body_velocities[0].linear, before.body_velocities[0].linear);
  // And it steps on from there.
  engine->Step(&world.state, 10);
  EXPECT_EQ(world.state.step, before.step + 10);
}

TEST(BulletEngineTest, CurvedTactilePadsAreRefused) {
  World world(PhysicsEngineKind::kBullet);
  world.Add(Link("p/base", 1, Vec3::Zero(), Mat3::Identity() * 1e-3), Pose());
  world.AddRobot("p", 0, 0);
  TactileArraySpec pad;
  pad.id = "p/pad";
  pad.body_id = "p/base";
  pad.bend_radius_x = 0.02;
  world.model->tactile_arrays.push_back(pad);
  world.model->Reindex();
  test_util::ExpectError([&] { MakePhysicsEngine(world.model); }, ErrorCode::kFailedPrecondition,
                         {"engine: bullet does not simulate curved tactile pads", "'p/pad'", "bend_radius 0.02 0"});
}

}  // namespace
}  // namespace graspsim
