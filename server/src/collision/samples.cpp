// Surface samples of boxes, spheres, cylinders and meshes (see samples.h).
#include "collision/samples.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <tuple>
#include <utility>

namespace graspsim::collision {
namespace {

// Intervals of at most `spacing` covering `size`. The relative slack keeps 0.05 / 0.005 (= 10.000000000000002
// in doubles) at 10 intervals instead of 11.
int Intervals(double size, double spacing) {
  if (size <= 0) return 0;
  return std::max(1, static_cast<int>(std::ceil(size / spacing * (1 - 1e-12))));
}

// Lattice coordinate i of n across [-half, half]; written so that i = 0 and i = n give exactly -half and half.
double Lattice(double half, int i, int n) { return n == 0 ? 0 : half * (static_cast<double>(2 * i - n) / n); }

// Points on a circle of `radius` needed for neighbours at most `spacing` apart (one at the centre).
int RingPoints(double radius, double spacing) {
  if (radius <= 0) return 1;
  return std::max(3, static_cast<int>(std::ceil(2 * std::numbers::pi * radius / spacing * (1 - 1e-12))));
}

double BoxCount(const Vec3& size, double spacing) {
  double all = 1, inner = 1;
  for (int k = 0; k < 3; ++k) {
    const int n = Intervals(size[k], spacing);
    all *= n + 1.0;
    inner *= std::max(n - 1, 0);
  }
  return all - inner;
}

std::vector<Vec3> SampleBox(const Vec3& size, double spacing) {
  const Vec3 half = 0.5 * size;
  const int nx = Intervals(size.x(), spacing), ny = Intervals(size.y(), spacing), nz = Intervals(size.z(), spacing);
  std::vector<Vec3> points;
  points.reserve(static_cast<size_t>(BoxCount(size, spacing)));
  for (int i = 0; i <= nx; ++i) {
    for (int j = 0; j <= ny; ++j) {
      const double x = Lattice(half.x(), i, nx), y = Lattice(half.y(), j, ny);
      // On a side face every lattice height is surface; inside the x-y outline only the top and bottom are.
      const bool side = i == 0 || i == nx || j == 0 || j == ny;
      for (int k = 0; k <= nz; k += (side || nz == 0) ? 1 : nz) points.emplace_back(x, y, Lattice(half.z(), k, nz));
    }
  }
  return points;
}

int SpherePoints(double radius, double spacing) {
  // One sample per spacing^2 of area puts Fibonacci neighbours about `spacing` apart.
  const double area = 4 * std::numbers::pi * radius * radius;
  return std::max(12, static_cast<int>(std::ceil(area / (spacing * spacing) * (1 - 1e-12))));
}

std::vector<Vec3> SampleSphere(double radius, double spacing) {
  const int n = SpherePoints(radius, spacing);
  const double golden_angle = std::numbers::pi * (3 - std::sqrt(5.0));
  std::vector<Vec3> points;
  points.reserve(n + 2);
  // The poles are the extreme points along z, where a sphere resting on a floor touches first.
  points.emplace_back(0, 0, -radius);
  for (int k = 0; k < n; ++k) {
    const double z = 1 - (2.0 * k + 1) / n;
    const double rho = std::sqrt(std::max(0.0, 1 - z * z));
    const double phi = golden_angle * k;
    points.emplace_back(radius * rho * std::cos(phi), radius * rho * std::sin(phi), -radius * z);
  }
  points.emplace_back(0, 0, radius);
  return points;
}

double CylinderCount(double radius, double length, double spacing) {
  const int nr = Intervals(radius, spacing), nz = Intervals(length, spacing);
  double cap = 0;
  for (int k = 0; k <= nr; ++k) cap += RingPoints(nr == 0 ? 0 : radius * k / nr, spacing);
  return (nz == 0 ? 1 : 2) * cap + std::max(nz - 1, 0) * static_cast<double>(RingPoints(radius, spacing));
}

std::vector<Vec3> SampleCylinder(double radius, double length, double spacing) {
  const int nr = Intervals(radius, spacing), nz = Intervals(length, spacing);
  const double half = 0.5 * length;
  std::vector<Vec3> points;
  points.reserve(static_cast<size_t>(CylinderCount(radius, length, spacing)));
  auto ring = [&](double r, double z) {
    const int m = RingPoints(r, spacing);
    for (int j = 0; j < m; ++j) {
      const double phi = 2 * std::numbers::pi * j / m;
      points.emplace_back(m == 1 ? 0 : r * std::cos(phi), m == 1 ? 0 : r * std::sin(phi), z);
    }
  };
  for (int i = 0; i <= nz; ++i) {
    const double z = Lattice(half, i, nz);
    if (i == 0 || i == nz) {
      for (int k = 0; k <= nr; ++k) ring(nr == 0 ? 0 : radius * k / nr, z);  // a cap, centre to rim
    } else {
      ring(radius, z);  // the side, at the rim's angles
    }
  }
  return points;
}

std::vector<Vec3> SampleMesh(const TriangleMesh& mesh) {
  // Only vertices that some triangle uses lie on the surface; equal positions count once.
  std::vector<Vec3> points;
  points.reserve(mesh.triangles.size() * 3);
  for (const auto& triangle : mesh.triangles) {
    for (uint32_t v : triangle) points.push_back(mesh.vertices[v].cast<double>());
  }
  auto less = [](const Vec3& a, const Vec3& b) {
    return std::tie(a.x(), a.y(), a.z()) < std::tie(b.x(), b.y(), b.z());
  };
  std::sort(points.begin(), points.end(), less);
  points.erase(std::unique(points.begin(), points.end()), points.end());
  return points;
}

// Spreads the low 10 bits of v to every third bit (Morton code helper).
uint32_t Spread10(uint32_t v) {
  v &= 0x3ff;
  v = (v | (v << 16)) & 0x030000ff;
  v = (v | (v << 8)) & 0x0300f00f;
  v = (v | (v << 4)) & 0x030c30c3;
  v = (v | (v << 2)) & 0x09249249;
  return v;
}

}  // namespace

std::vector<Vec3> SampleGeometry(const Geometry& geometry, double spacing) {
  switch (geometry.kind) {
    case Geometry::Kind::kBox:
      while (BoxCount(geometry.box_size, spacing) > kMaxSamplesPerPrimitive) spacing *= 2;
      return SampleBox(geometry.box_size, spacing);
    case Geometry::Kind::kSphere:
      while (SpherePoints(geometry.radius, spacing) + 2.0 > kMaxSamplesPerPrimitive) spacing *= 2;
      return SampleSphere(geometry.radius, spacing);
    case Geometry::Kind::kCylinder:
      while (CylinderCount(geometry.radius, geometry.length, spacing) > kMaxSamplesPerPrimitive) spacing *= 2;
      return SampleCylinder(geometry.radius, geometry.length, spacing);
    case Geometry::Kind::kMesh:
      return geometry.mesh ? SampleMesh(*geometry.mesh) : std::vector<Vec3>{};
  }
  return {};
}

Aabb GeometryBounds(const Geometry& geometry) {
  switch (geometry.kind) {
    case Geometry::Kind::kBox:
      return {-0.5 * geometry.box_size, 0.5 * geometry.box_size};
    case Geometry::Kind::kSphere:
      return {Vec3::Constant(-geometry.radius), Vec3::Constant(geometry.radius)};
    case Geometry::Kind::kCylinder: {
      const Vec3 half(geometry.radius, geometry.radius, 0.5 * geometry.length);
      return {-half, half};
    }
    case Geometry::Kind::kMesh: {
      Aabb box;
      if (geometry.mesh) {
        for (const auto& v : geometry.mesh->vertices) box.Add(v.cast<double>());
      }
      return box;
    }
  }
  return {};
}

BodySamples SampleBody(const BodySpec& body, double spacing) {
  BodySamples out;
  for (size_t g = 0; g < body.collision.size(); ++g) {
    const Geometry& geometry = body.collision[g];
    std::vector<Vec3> points = SampleGeometry(geometry, spacing);
    if (points.empty()) continue;
    const Mat3 rotation = geometry.origin.orientation.toRotationMatrix();
    Aabb bounds;
    for (Vec3& p : points) {
      p = rotation * p + geometry.origin.position;
      bounds.Add(p);
    }
    // Morton order makes consecutive samples neighbours in space, so a block of them has a small box.
    const Vec3 scale = (1023.0 / (bounds.hi - bounds.lo).array().max(1e-12)).matrix();
    std::vector<std::pair<uint32_t, uint32_t>> keyed(points.size());
    for (size_t k = 0; k < points.size(); ++k) {
      const Vec3 q = (points[k] - bounds.lo).cwiseProduct(scale);
      const uint32_t code = Spread10(static_cast<uint32_t>(q.x())) | Spread10(static_cast<uint32_t>(q.y())) << 1 |
                            Spread10(static_cast<uint32_t>(q.z())) << 2;
      keyed[k] = {code, static_cast<uint32_t>(k)};
    }
    std::sort(keyed.begin(), keyed.end());  // ties broken by the original index: deterministic
    for (uint32_t k = 0; k < keyed.size(); ++k) {
      if (k % kBlockSize == 0) out.blocks.push_back({{}, static_cast<uint32_t>(out.points.size()), 0});
      SampleBlock& block = out.blocks.back();
      out.points.push_back(points[keyed[k].second]);
      out.features.push_back(static_cast<uint64_t>(g) << 32 | k);
      block.bounds.Add(out.points.back());
      block.end = static_cast<uint32_t>(out.points.size());
    }
  }
  for (uint32_t b = 0; b < out.blocks.size(); ++b) {
    if (b % kBlocksPerGroup == 0) out.groups.push_back({{}, b, b});
    out.groups.back().bounds.Add(out.blocks[b].bounds);
    out.groups.back().end = b + 1;
  }
  return out;
}

}  // namespace graspsim::collision
