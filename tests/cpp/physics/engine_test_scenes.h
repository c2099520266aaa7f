// Scenes built in code for the engine backend suites (physics/bullet_engine_test.cpp, physics/mujoco_engine_test.cpp):
// bodies, links, box meshes and a World that collects them and starts an engine of a given kind.
#pragma once

#include <memory>
#include <string>
#include <utility>

#include "cpp/test_bodies.h"
#include "physics/engine.h"
#include "world/model.h"
#include "world/state.h"

namespace graspsim::test_engines {

// A free sphere of uniform density: inertia 2/5 m r² about each axis.
inline BodySpec Sphere(const std::string& id, double radius, double mass) {
  BodySpec body;
  body.id = id;
  body.motion = BodyMotion::kFree;
  Geometry sphere;
  sphere.kind = Geometry::Kind::kSphere;
  sphere.radius = radius;
  body.collision.push_back(sphere);
  body.inertial.mass = mass;
  body.inertial.inertia = Mat3::Identity() * (0.4 * mass * radius * radius);
  return body;
}

// A robot link "<robot>/<name>" without geometry: mass, centre of mass and inertia about it (link frame).
inline BodySpec Link(const std::string& id, double mass, const Vec3& com, const Mat3& inertia) {
  BodySpec body;
  body.id = id;
  body.robot_id = id.substr(0, id.find('/'));
  body.motion = BodyMotion::kArticulated;
  body.inertial.mass = mass;
  body.inertial.center_of_mass = com;
  body.inertial.inertia = inertia;
  return body;
}

// A closed box mesh centred on its frame (12 triangles, counter-clockwise from outside).
inline std::shared_ptr<const TriangleMesh> BoxMesh(const Vec3& size) {
  auto mesh = std::make_shared<TriangleMesh>();
  for (int i = 0; i < 8; ++i) {
    mesh->vertices.emplace_back(Eigen::Vector3f((i & 1 ? 0.5f : -0.5f) * static_cast<float>(size.x()),
                                                (i & 2 ? 0.5f : -0.5f) * static_cast<float>(size.y()),
                                                (i & 4 ? 0.5f : -0.5f) * static_cast<float>(size.z())));
  }
  mesh->triangles = {{0, 2, 1}, {1, 2, 3}, {4, 5, 6}, {5, 7, 6}, {0, 1, 4}, {1, 5, 4},
                     {2, 6, 3}, {3, 6, 7}, {0, 4, 2}, {2, 4, 6}, {1, 3, 5}, {3, 7, 5}};
  return mesh;
}

// `body` with each of its boxes turned into the same box as a triangle mesh.
inline BodySpec MeshBody(BodySpec body) {
  for (Geometry& g : body.collision) {
    g.mesh = BoxMesh(g.box_size);
    g.kind = Geometry::Kind::kMesh;
  }
  return body;
}

// A scene model and its state, built body by body, run on the engine `kind`.
struct World {
  std::shared_ptr<SceneModel> model = std::make_shared<SceneModel>();
  SceneState state;

  explicit World(PhysicsEngineKind kind) { model->simulation.engine = kind; }
  size_t Add(BodySpec body, const Pose& pose) {
    model->bodies.push_back(std::move(body));
    state.body_poses.push_back(pose);
    return model->bodies.size() - 1;
  }
  // A robot of the bodies and joints added since `first_body` / `first_joint` (topological order).
  void AddRobot(const std::string& id, size_t first_body, size_t first_joint) {
    RobotSpec robot{id, "test", model->bodies[first_body].id, {}, {}, {}};
    for (size_t i = first_body; i < model->bodies.size(); ++i) robot.body_ids.push_back(model->bodies[i].id);
    for (size_t j = first_joint; j < model->joints.size(); ++j) robot.joint_ids.push_back(model->joints[j].id);
    model->robots.push_back(robot);
  }
  // Indexes the model, places the links by forward kinematics and compiles the engine (state prepared for it).
  std::shared_ptr<PhysicsEngine> Start() {
    model->Reindex();
    state.joint_positions.resize(model->joints.size(), 0);
    for (size_t r = 0; r < model->robots.size(); ++r) UpdateRobotLinkPoses(*model, r, &state);
    std::shared_ptr<PhysicsEngine> engine = MakePhysicsEngine(model);
    engine->PrepareState(&state);
    return engine;
  }
};

// One light link on a vertical hinge (no gravity torque: its centre of mass lies beside the z axis), driven at
// 0.5 rad/s by the default motor with the current and voltage limits raised so the drive stays linear: a step
// of the PI loop gives f0 = 5 N m/V · (50 · 0.5 + 500 · 0.5 h) V = 126.25 N m and damps by
// D = −5 (50 + 500 h + 5) = −277.5 N m s/rad (physics/actuators.cpp), against I = 1e-4 + 0.2 · 0.05² kg m².
constexpr double kLightInertia = 1e-4 + 0.2 * 0.05 * 0.05;
inline World DrivenLink(PhysicsEngineKind engine, Integrator integrator) {
  World world(engine);
  world.model->simulation.integrator = integrator;
  world.Add(Link("d/base", 1, Vec3::Zero(), Mat3::Identity() * 1e-3), Pose{Vec3(0, 0, 1), Quat::Identity()});
  world.Add(Link("d/arm", 0.2, Vec3(0.05, 0, 0), Mat3::Identity() * 1e-4), Pose());
  world.model->joints.push_back(test_objects::RobotJoint("d/hinge", JointType::kRevolute, "d/base", "d/arm",
                                                         Pose{Vec3(0, 0.1, 0), Quat::Identity()}, Vec3::UnitZ()));
  world.AddRobot("d", 0, 0);
  JointActuator& drive = world.state.actuators[0];
  drive.motor.current_limit = 100;
  drive.motor.voltage_limit = 48;
  drive.command = {ActuatorMode::kVelocity, 0.5, -1};
  return world;
}

// DrivenLink's velocity after its first 1 ms step of implicit Euler, v1 = h f0 / (I − h D) = 0.45397 rad/s: what
// an engine that takes the drive implicitly gives (an explicit step diverges: h |D| / I ≈ 460).
constexpr double kDrivenLinkFirstStepVelocity = 1e-3 * 126.25 / (kLightInertia + 1e-3 * 277.5);

// DrivenLink on graspsim's engine (linearly implicit Euler) after `steps` steps: the reference the other engines'
// drives are held to (same motor model, same implicit step).
inline SceneState GraspsimDrivenLinkAfter(int steps) {
  World reference = DrivenLink(PhysicsEngineKind::kGraspsim, Integrator::kLinearlyImplicitEuler);
  reference.Start()->Step(&reference.state, steps);
  return reference.state;
}

}  // namespace graspsim::test_engines
