// Scenes for the motion suites: a built-in arm (with or without a hand) on the floor or a table.
#pragma once

#include <memory>
#include <string>

#include "cpp/collision/collision_fixtures.h"
#include "collision/tessellation.h"
#include "core/limits.h"
#include "motion/arm.h"
#include "import/robot_import.h"
#include "world/loaders.h"
#include "world/scene.h"

namespace graspsim::motion_test {

struct ArmScene {
  std::unique_ptr<Scene> scene;
  SceneView view;
};

// `model` a built-in robot placed as robot "arm" at `base`; `extra` runs on the scene before the view is taken.
template <typename Extra>
ArmScene MakeArmScene(const std::string& model, const Pose& base, Extra&& extra) {
  ArmScene out;
  out.scene = std::make_unique<Scene>("s", "s", Limits());
  out.scene->AddRobot("arm", "builtin:" + model, LoadUrdf(BuiltinModelUrdf(model), nullptr, Limits()), base);
  extra(out.scene.get());
  out.view = out.scene->View();
  return out;
}

inline ArmScene MakeArmScene(const std::string& model, const Pose& base = {}) {
  return MakeArmScene(model, base, [](Scene*) {});
}

// A static obstacle of one primitive.
inline void AddStatic(Scene* scene, const std::string& id, const Geometry& geometry, const Pose& pose) {
  BodySpec body;
  body.id = id;
  body.motion = BodyMotion::kStatic;
  body.collision.push_back(geometry);
  body.inertial.mass = 1;
  body.inertial.inertia = Mat3::Identity() * 1e-3;
  scene->AddObject(body, pose);
}

// Primitive shapes: the collision suites' builders.
using collision_fixtures::BoxGeometry;
using collision_fixtures::CylinderGeometry;
using collision_fixtures::SphereGeometry;

inline Pose At(double x, double y, double z) { return {Vec3(x, y, z), Quat::Identity()}; }

// A closed mesh: the tessellated sphere of `radius` (an object the planner sees through a distance grid).
inline Geometry MeshBall(double radius) {
  const collision::LocalMesh local = collision::SphereMesh(radius);
  auto mesh = std::make_shared<TriangleMesh>();
  for (const Vec3& v : local.vertices) mesh->vertices.push_back(v.cast<float>());
  mesh->triangles = local.triangles;
  Geometry g;
  g.kind = Geometry::Kind::kMesh;
  g.mesh = mesh;
  return g;
}

// The arm on a table (top 1.2 x 0.8 m, surface at z = 0.75, centred at the origin), its base at x = -0.45.
// Clutter: a tall box, a ball, a cylinder and a mesh ball on the table ahead of the arm.
inline ArmScene TableScene(const std::string& model) {
  return MakeArmScene(model, At(-0.45, 0, 0.75), [](Scene* scene) {
    AddStatic(scene, "table", BoxGeometry(Vec3(1.2, 0.8, 0.04)), At(0, 0, 0.73));
    AddStatic(scene, "post", BoxGeometry(Vec3(0.06, 0.06, 0.40)), At(0.0, 0.0, 0.95));
    AddStatic(scene, "ball", SphereGeometry(0.06), At(0.05, 0.25, 0.81));
    AddStatic(scene, "can", CylinderGeometry(0.04, 0.16), At(0.05, -0.25, 0.83));
    AddStatic(scene, "melon", MeshBall(0.07), At(0.25, 0.1, 0.82));
  });
}

}  // namespace graspsim::motion_test
