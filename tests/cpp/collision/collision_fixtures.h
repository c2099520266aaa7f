// Hand-built bodies and meshes shared by the collision suites.
#pragma once

#include <cmath>
#include <memory>
#include <numbers>
#include <string>

#include "world/model.h"

namespace graspsim::collision_fixtures {

inline BodySpec Body(const std::string& id, const Geometry& geometry, BodyMotion motion = BodyMotion::kFree) {
  BodySpec body;
  body.id = id;
  body.motion = motion;
  body.collision.push_back(geometry);
  body.inertial.mass = 0.1;
  body.inertial.inertia = Mat3::Identity() * 1e-5;
  return body;
}

inline Geometry BoxGeometry(const Vec3& size) {
  Geometry g;
  g.kind = Geometry::Kind::kBox;
  g.box_size = size;
  return g;
}

inline Geometry SphereGeometry(double radius) {
  Geometry g;
  g.kind = Geometry::Kind::kSphere;
  g.radius = radius;
  return g;
}

inline Geometry CylinderGeometry(double radius, double length) {
  Geometry g;
  g.kind = Geometry::Kind::kCylinder;
  g.radius = radius;
  g.length = length;
  return g;
}

// A closed 12-triangle box mesh centred on its frame, counter-clockwise seen from outside.
inline std::shared_ptr<const TriangleMesh> BoxMesh(const Vec3& size) {
  auto mesh = std::make_shared<TriangleMesh>();
  const Eigen::Vector3f h = (0.5 * size).cast<float>();
  for (int k = 0; k < 8; ++k) {
    const float x = (k == 1 || k == 2 || k == 5 || k == 6) ? h.x() : -h.x();
    const float y = (k == 2 || k == 3 || k == 6 || k == 7) ? h.y() : -h.y();
    mesh->vertices.emplace_back(x, y, k < 4 ? -h.z() : h.z());
  }
  mesh->triangles = {{0, 2, 1}, {0, 3, 2}, {4, 5, 6}, {4, 6, 7}, {0, 1, 5}, {0, 5, 4},
                     {3, 7, 6}, {3, 6, 2}, {0, 4, 7}, {0, 7, 3}, {1, 2, 6}, {1, 6, 5}};
  return mesh;
}

// A closed UV sphere with 2 * slices * (stacks - 1) triangles.
inline std::shared_ptr<const TriangleMesh> SphereMesh(double radius, int slices, int stacks) {
  auto mesh = std::make_shared<TriangleMesh>();
  mesh->vertices.emplace_back(0.f, 0.f, static_cast<float>(-radius));  // 0: south pole
  for (int i = 1; i < stacks; ++i) {
    const double theta = std::numbers::pi * i / stacks;  // from the south pole
    for (int j = 0; j < slices; ++j) {
      const double phi = 2 * std::numbers::pi * j / slices;
      mesh->vertices.emplace_back(static_cast<float>(radius * std::sin(theta) * std::cos(phi)),
                                  static_cast<float>(radius * std::sin(theta) * std::sin(phi)),
                                  static_cast<float>(-radius * std::cos(theta)));
    }
  }
  const uint32_t north = static_cast<uint32_t>(mesh->vertices.size());
  mesh->vertices.emplace_back(0.f, 0.f, static_cast<float>(radius));
  auto ring = [&](int i, int j) { return static_cast<uint32_t>(1 + (i - 1) * slices + (j % slices)); };
  for (int j = 0; j < slices; ++j) {
    mesh->triangles.push_back({0, ring(1, j + 1), ring(1, j)});
    for (int i = 1; i + 1 < stacks; ++i) {
      mesh->triangles.push_back({ring(i, j), ring(i, j + 1), ring(i + 1, j + 1)});
      mesh->triangles.push_back({ring(i, j), ring(i + 1, j + 1), ring(i + 1, j)});
    }
    mesh->triangles.push_back({north, ring(stacks - 1, j), ring(stacks - 1, j + 1)});
  }
  return mesh;
}

inline Geometry MeshGeometry(std::shared_ptr<const TriangleMesh> mesh) {
  Geometry g;
  g.kind = Geometry::Kind::kMesh;
  g.mesh = std::move(mesh);
  return g;
}

inline SceneModel Model(std::vector<BodySpec> bodies) {
  SceneModel model;
  model.bodies = std::move(bodies);
  model.Reindex();
  return model;
}

inline Pose At(double x, double y, double z, const Quat& q = Quat::Identity()) { return {Vec3(x, y, z), q}; }

}  // namespace graspsim::collision_fixtures
