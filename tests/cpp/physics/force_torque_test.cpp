// The 6-axis force/torque sensor on a joint (SceneState::joint_wrenches, sensors/readings.h): the wrench the
// joint transmits to its child side, in the child frame, torque about the child frame's origin. Statics of a
// welded arm, a load carried through a stand's flange onto a tactile pad, and a swinging pendulum's closed form.
#include <cmath>

#include <gtest/gtest.h>

#include "physics/simulation.h"
#include "sensors/readings.h"
#include "test_bodies.h"

namespace graspsim {
namespace {

constexpr double kG = 9.81;
const Vec3 kGravity(0, 0, -kG);

BodySpec Link(const std::string& id, double mass, const Vec3& com, const Vec3& inertia) {
  BodySpec body;
  body.id = id;
  body.robot_id = id.substr(0, id.find('/'));
  body.motion = BodyMotion::kArticulated;
  body.inertial.mass = mass;
  body.inertial.center_of_mass = com;
  body.inertial.inertia = inertia.asDiagonal();
  return body;
}

using test_objects::RobotJoint;

void ExpectNearVec(const Vec3& actual, const Vec3& expected, double tolerance, const std::string& what) {
  EXPECT_LE((actual - expected).norm(), tolerance) << what << ": " << actual.transpose() << " vs "
                                                   << expected.transpose();
}

TEST(ForceTorqueTest, WeldedArmAtRestCarriesTheWeightOfItsSubtree) {
  // base (rotated, welded) → shoulder (revolute, its axis vertical in the world, so gravity does not turn it) →
  // upper (2 kg, CoM off the axis) → flange (fixed, rotated origin) → hand (0.7 kg, CoM off the flange). The
  // shoulder carries both links, the flange the hand: force −(Σm) g, torque −Σ (c − o) × m g, child frame.
  const Quat base_rotation(Eigen::AngleAxisd(0.4, Vec3(1, -2, 0.5).normalized()));
  const Pose shoulder_origin{Vec3(0.05, -0.02, 0.1), Quat(Eigen::AngleAxisd(0.7, Vec3(0.3, 1, 0).normalized()))};
  // The shoulder axis in its joint frame: world z.
  const Vec3 axis = (base_rotation * shoulder_origin.orientation).conjugate() * Vec3::UnitZ();
  const Pose flange_origin{Vec3(0.3, 0.1, -0.05), Quat(Eigen::AngleAxisd(-1.1, Vec3(1, 0.2, 0.7).normalized()))};
  auto model = std::make_shared<SceneModel>();
  model->bodies = {Link("arm/base", 3, Vec3::Zero(), Vec3(0.01, 0.01, 0.01)),
                   Link("arm/upper", 2, Vec3(0.15, 0.05, -0.02), Vec3(0.02, 0.03, 0.01)),
                   Link("arm/hand", 0.7, Vec3(0.02, -0.03, 0.08), Vec3(0.002, 0.003, 0.001))};
  model->joints = {RobotJoint("arm/shoulder", JointType::kRevolute, "arm/base", "arm/upper", shoulder_origin, axis),
                   RobotJoint("arm/flange", JointType::kFixed, "arm/upper", "arm/hand", flange_origin, Vec3::UnitX())};
  model->robots = {RobotSpec{"arm", "test", "arm/base", {"arm/base", "arm/upper", "arm/hand"},
                             {"arm/shoulder", "arm/flange"}, {}}};
  model->simulation.gravity = kGravity;
  model->Reindex();
  for (Integrator integrator : {Integrator::kLinearlyImplicitEuler, Integrator::kSemiImplicitEuler,
                                Integrator::kVelocityVerlet}) {
    model->simulation.integrator = integrator;
    SceneState state;
    state.body_poses = {Pose{Vec3(0.2, -0.1, 0.8), base_rotation}, Pose{}, Pose{}};
    state.joint_positions = {0.6, 0};
    UpdateRobotLinkPoses(*model, 0, &state);
    Simulation simulation(model);
    simulation.PrepareState(&state);
    EXPECT_EQ(ReadForceTorque(*model, state, 0).force, Vec3::Zero()) << "zero before the first step";
    simulation.Step(&state, 50);
    auto expected = [&](size_t child, std::vector<size_t> carried) {
      const Pose& frame = state.body_poses[child];
      Vec3 force = Vec3::Zero(), torque = Vec3::Zero();
      for (size_t b : carried) {
        const Vec3 weight = model->bodies[b].inertial.mass * kGravity;
        force -= weight;
        torque -= (state.body_poses[b] * model->bodies[b].inertial.center_of_mass - frame.position).cross(weight);
      }
      return std::pair{frame.orientation.conjugate() * force, frame.orientation.conjugate() * torque};
    };
    const auto [shoulder_force, shoulder_torque] = expected(1, {1, 2});
    const auto [flange_force, flange_torque] = expected(2, {2});
    const ForceTorqueReading shoulder = ReadForceTorque(*model, state, 0), flange = ReadForceTorque(*model, state, 1);
    ExpectNearVec(shoulder.force, shoulder_force, 1e-9 * shoulder_force.norm(), "shoulder force");
    ExpectNearVec(shoulder.torque, shoulder_torque, 1e-9 * shoulder_torque.norm(), "shoulder torque");
    ExpectNearVec(flange.force, flange_force, 1e-9 * flange_force.norm(), "flange force");
    ExpectNearVec(flange.torque, flange_torque, 1e-9 * flange_torque.norm(), "flange torque");
    // Not vacuous: the frames are rotated and the moments are large.
    EXPECT_GT((flange.force - Vec3(0, 0, 0.7 * kG)).norm(), 1.0) << "the world-frame force would pass";
    EXPECT_GT(shoulder_torque.norm(), 1.0);
    EXPECT_NEAR(state.joint_positions[0], 0.6, 1e-12) << "the arm stays at rest";
  }
}

TEST(ForceTorqueTest, AFlangeCarriesTheLoadRestingOnItsPad) {
  // A welded stand whose plate (0.5 kg, CoM 1 cm off centre) hangs on a flange joint and carries a DSA 9205-like
  // pad facing up; a 0.2 kg box settles on the foam. The flange then carries plate and box: within 0.5 %.
  for (JointType type : {JointType::kFixed, JointType::kRevolute}) {
    auto model = std::make_shared<SceneModel>();
    model->bodies = {Link("stand/base", 1, Vec3::Zero(), Vec3(1e-3, 1e-3, 1e-3)),
                     Link("stand/plate", 0.5, Vec3(0.01, 0, -0.005), Vec3(1e-3, 1e-3, 1e-3))};
    BodySpec box;
    box.id = "box";
    box.motion = BodyMotion::kFree;
    Geometry geometry;
    geometry.box_size = Vec3(0.03, 0.06, 0.02);
    box.collision.push_back(geometry);
    box.inertial.mass = 0.2;
    box.inertial.inertia = Vec3(0.004, 0.0013, 0.0045).asDiagonal() * (0.2 / 12);
    model->bodies.push_back(box);
    // A revolute flange turns about the vertical: the load does not turn it.
    model->joints = {RobotJoint("stand/flange", type, "stand/base", "stand/plate", Pose(), Vec3::UnitZ())};
    TactileArraySpec pad;
    pad.id = "stand/pad";
    pad.body_id = "stand/plate";
    pad.rows = 14;
    pad.cols = 6;
    pad.pitch = 0.0034;
    pad.thickness = 0.004;
    pad.subdivision = 1;
    model->tactile_arrays.push_back(pad);
    model->robots.push_back(
        RobotSpec{"stand", "test", "stand/base", {"stand/base", "stand/plate"}, {"stand/flange"}, {"stand/pad"}});
    model->simulation.sleep_time = 0;
    model->Reindex();
    SceneState state;
    state.body_poses = {Pose(), Pose(), {Vec3(0.002, 0, pad.thickness + 0.01 - 1e-6), Quat::Identity()}};
    state.joint_positions = {0};
    Simulation simulation(model);
    simulation.PrepareState(&state);
    simulation.Step(&state, 1000);
    const ForceTorqueReading reading = ReadForceTorque(*model, state, 0);
    const double load = (0.5 + 0.2) * kG;
    EXPECT_NEAR(reading.force.z() / load, 1.0, 5e-3);
    EXPECT_NEAR(std::hypot(reading.force.x(), reading.force.y()), 0, 1e-3 * load);
    // The moment about the flange's origin: plate CoM at x = 1 cm, box centred near x = 2 mm: about −y.
    const double moment = -(0.5 * kG * 0.01 + 0.2 * kG * state.body_poses[2].position.x());
    EXPECT_NEAR(reading.torque.y() / moment, 1.0, 0.01);
    // And the pad agrees: what the elements feel is the box's share.
    Vec3 pad_force = Vec3::Zero();
    for (const Vec3& f : state.pad_forces[0]) pad_force += f;
    EXPECT_NEAR(reading.force.z() - 0.5 * kG, -pad_force.z(), 1e-6 * load);
  }
}

TEST(ForceTorqueTest, SwingingPendulumMatchesTheClosedForm) {
  // A link l below a y hinge, released at 1 rad. In the child frame (rotating with the link, the link along −z):
  // the hinge pulls along +z with m (g cos θ + ω² l), along x with I_c θ̈ / l (the moment about the CoM), and
  // transmits no torque about the pivot (diagonal inertia: the motion stays planar).
  const double m = 1.5, l = 0.4, inertia = 0.02;
  auto model = std::make_shared<SceneModel>();
  model->bodies = {Link("p/base", 1, Vec3::Zero(), Vec3(1, 1, 1)),
                   Link("p/bob", m, Vec3(0, 0, -l), Vec3(0.01, inertia, 0.015))};
  model->joints = {RobotJoint("p/hinge", JointType::kRevolute, "p/base", "p/bob", Pose(), Vec3::UnitY())};
  model->robots = {RobotSpec{"p", "test", "p/base", {"p/base", "p/bob"}, {"p/hinge"}, {}}};
  model->simulation.gravity = kGravity;
  model->simulation.time_step = 1e-4;
  model->simulation.substeps = 1;
  model->simulation.integrator = Integrator::kSemiImplicitEuler;
  model->Reindex();
  SceneState state;
  state.body_poses = {Pose{Vec3(0, 0, 1), Quat::Identity()}, Pose{}};
  state.joint_positions = {1.0};
  UpdateRobotLinkPoses(*model, 0, &state);
  Simulation simulation(model);
  simulation.PrepareState(&state);
  double fastest = 0;
  for (int k = 0; k < 20; ++k) {
    simulation.Step(&state, 150);
    const double theta = state.joint_positions[0], omega = state.joint_velocities[0];
    fastest = std::max(fastest, std::abs(omega));
    const double alpha = -m * kG * l * std::sin(theta) / (inertia + m * l * l);
    const Vec3 expected(inertia * alpha / l, 0, m * (kG * std::cos(theta) + omega * omega * l));
    const ForceTorqueReading reading = ReadForceTorque(*model, state, 0);
    ExpectNearVec(reading.force, expected, 1e-3 * m * kG, "t = " + std::to_string(state.time));
    EXPECT_NEAR(reading.force.norm() / expected.norm(), 1.0, 1e-3);
    EXPECT_LE(reading.torque.norm(), 1e-9 * m * kG * l);
  }
  EXPECT_GT(fastest, 1.5) << "it swings";
}

}  // namespace
}  // namespace graspsim
