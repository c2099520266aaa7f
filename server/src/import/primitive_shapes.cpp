// Shapes graspsim has no primitive for, from its own (primitive_shapes.h).
#include "import/primitive_shapes.h"

#include <array>
#include <cmath>
#include <map>
#include <utility>

namespace graspsim::import {

std::vector<Geometry> CapsuleGeometries(double radius, double length, const Pose& origin) {
  std::vector<Geometry> parts(3);
  parts[0].kind = Geometry::Kind::kCylinder;
  parts[0].radius = radius;
  parts[0].length = length;
  parts[0].origin = origin;
  for (int end = 0; end < 2; ++end) {
    Geometry& sphere = parts[1 + end];
    sphere.kind = Geometry::Kind::kSphere;
    sphere.radius = radius;
    sphere.origin = origin * Pose{Vec3(0, 0, (end == 0 ? 0.5 : -0.5) * length), Quat::Identity()};
  }
  return parts;
}

std::shared_ptr<const TriangleMesh> EllipsoidMesh(const Vec3& radii) {
  // The unit icosahedron, subdivided twice (each triangle into 4, new vertices pushed onto the sphere).
  const double t = (1 + std::sqrt(5.0)) / 2;
  std::vector<Vec3> points = {{-1, t, 0}, {1, t, 0},  {-1, -t, 0}, {1, -t, 0}, {0, -1, t},  {0, 1, t},
                              {0, -1, -t}, {0, 1, -t}, {t, 0, -1},  {t, 0, 1},  {-t, 0, -1}, {-t, 0, 1}};
  for (Vec3& p : points) p.normalize();
  std::vector<std::array<uint32_t, 3>> faces = {
      {0, 11, 5}, {0, 5, 1},  {0, 1, 7},   {0, 7, 10}, {0, 10, 11}, {1, 5, 9}, {5, 11, 4},
      {11, 10, 2}, {10, 7, 6}, {7, 1, 8},  {3, 9, 4},  {3, 4, 2},   {3, 2, 6}, {3, 6, 8},
      {3, 8, 9},  {4, 9, 5},  {2, 4, 11}, {6, 2, 10}, {8, 6, 7},   {9, 8, 1}};
  for (int level = 0; level < 2; ++level) {
    std::map<std::pair<uint32_t, uint32_t>, uint32_t> midpoints;
    const auto midpoint = [&](uint32_t a, uint32_t b) {
      const auto key = std::minmax(a, b);
      const auto [it, inserted] = midpoints.emplace(key, static_cast<uint32_t>(points.size()));
      if (inserted) points.push_back((points[a] + points[b]).normalized());
      return it->second;
    };
    std::vector<std::array<uint32_t, 3>> finer;
    finer.reserve(faces.size() * 4);
    for (const auto& f : faces) {
      const uint32_t ab = midpoint(f[0], f[1]), bc = midpoint(f[1], f[2]), ca = midpoint(f[2], f[0]);
      finer.push_back({f[0], ab, ca});
      finer.push_back({f[1], bc, ab});
      finer.push_back({f[2], ca, bc});
      finer.push_back({ab, bc, ca});
    }
    faces = std::move(finer);
  }
  auto mesh = std::make_shared<TriangleMesh>();
  mesh->vertices.reserve(points.size());
  for (const Vec3& p : points) mesh->vertices.push_back(p.cwiseProduct(radii).cast<float>());
  mesh->triangles = std::move(faces);
  return mesh;
}

Geometry PlaneBox(const Vec3& normal, double size_x, double size_y, const Pose& origin) {
  Geometry box;
  box.kind = Geometry::Kind::kBox;
  box.box_size = Vec3(size_x, size_y, kPlaneThickness);
  const Quat tilt = Quat::FromTwoVectors(Vec3::UnitZ(), normal.normalized());
  box.origin = origin * Pose{tilt * Vec3(0, 0, -0.5 * kPlaneThickness), tilt};
  return box;
}

}  // namespace graspsim::import
