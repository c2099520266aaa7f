// Analytic test shapes for the perception suites: points with exact outward normals, the exact distance to the
// surface, and the exact volume. Sampling is deterministic (spirals and grids, no random numbers).
#pragma once

#include <algorithm>
#include <cmath>
#include <vector>

#include "core/math.h"

namespace graspsim::test_shapes {

struct OrientedCloud {
  std::vector<Vec3> points, normals;
};

// A sphere of radius r about `centre`, n points on a Fibonacci spiral (even spacing, no poles clustered).
inline OrientedCloud Sphere(double r, int n, const Vec3& centre = Vec3::Zero()) {
  OrientedCloud cloud;
  const double golden = M_PI * (3 - std::sqrt(5.0));
  for (int i = 0; i < n; ++i) {
    const double z = 1 - (2 * i + 1.0) / n, rho = std::sqrt(1 - z * z);
    const Vec3 u(rho * std::cos(golden * i), rho * std::sin(golden * i), z);
    cloud.points.push_back(centre + r * u);
    cloud.normals.push_back(u);
  }
  return cloud;
}
inline double SphereDistance(const Vec3& p, double r, const Vec3& centre = Vec3::Zero()) {
  return std::abs((p - centre).norm() - r);
}

// An axis-aligned box of the given size about the origin, each face a grid of `spacing` (cell centres).
inline OrientedCloud Box(const Vec3& size, double spacing) {
  OrientedCloud cloud;
  for (int axis = 0; axis < 3; ++axis) {
    const int u = (axis + 1) % 3, v = (axis + 2) % 3;
    const int nu = std::max(1, int(std::round(size[u] / spacing))), nv = std::max(1, int(std::round(size[v] / spacing)));
    for (int side : {-1, 1}) {
      for (int i = 0; i < nu; ++i) {
        for (int j = 0; j < nv; ++j) {
          Vec3 p = Vec3::Zero(), n = Vec3::Zero();
          p[axis] = side * size[axis] / 2;
          p[u] = -size[u] / 2 + (i + 0.5) * size[u] / nu;
          p[v] = -size[v] / 2 + (j + 0.5) * size[v] / nv;
          n[axis] = side;
          cloud.points.push_back(p);
          cloud.normals.push_back(n);
        }
      }
    }
  }
  return cloud;
}
inline double BoxDistance(const Vec3& p, const Vec3& size) {
  const Vec3 q = p.cwiseAbs() - size / 2;
  const double outside = q.cwiseMax(0.0).norm();
  return outside > 0 ? outside : -q.maxCoeff();
}

// A closed cylinder along z (radius r, height h) about the origin: rings on the side, spirals on the caps.
inline OrientedCloud Cylinder(double r, double h, double spacing) {
  OrientedCloud cloud;
  const int around = int(std::round(2 * M_PI * r / spacing)), rings = int(std::round(h / spacing));
  for (int k = 0; k < rings; ++k) {
    for (int i = 0; i < around; ++i) {
      const double a = 2 * M_PI * (i + 0.5 * (k % 2)) / around;
      cloud.points.emplace_back(r * std::cos(a), r * std::sin(a), -h / 2 + (k + 0.5) * h / rings);
      cloud.normals.emplace_back(std::cos(a), std::sin(a), 0);
    }
  }
  const int cap = int(std::round(M_PI * r * r / (spacing * spacing)));
  const double golden = M_PI * (3 - std::sqrt(5.0));
  for (int side : {-1, 1}) {
    for (int i = 0; i < cap; ++i) {
      const double rho = r * std::sqrt((i + 0.5) / cap);
      cloud.points.emplace_back(rho * std::cos(golden * i), rho * std::sin(golden * i), side * h / 2);
      cloud.normals.emplace_back(0, 0, side);
    }
  }
  return cloud;
}
inline double CylinderDistance(const Vec3& p, double r, double h) {
  const double radial = std::hypot(p.x(), p.y()) - r, axial = std::abs(p.z()) - h / 2;
  if (radial > 0 || axial > 0) return std::hypot(std::max(radial, 0.0), std::max(axial, 0.0));
  return -std::max(radial, axial);
}

}  // namespace graspsim::test_shapes
