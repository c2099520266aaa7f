#include "collision/tessellation.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <unordered_map>

#include "collision/mesh_query.h"

namespace graspsim::collision {
namespace {

// Largest gap allowed between a tessellated sphere or cylinder and the true surface, m.
constexpr double kChordError = 1e-4;
// A 10 m sphere at 0.1 mm would need millions of triangles; beyond this a primitive stays coarser than kChordError.
constexpr size_t kMaxTrianglesPerPrimitive = size_t{1} << 21;

// Primitives are convex and centred on their frame: a triangle whose normal points toward the centre is flipped,
// so every primitive comes out counter-clockwise seen from outside whatever order the builder used.
void OrientOutward(LocalMesh* mesh) {
  for (auto& t : mesh->triangles) {
    const Vec3& a = mesh->vertices[t[0]];
    const Vec3& b = mesh->vertices[t[1]];
    const Vec3& c = mesh->vertices[t[2]];
    if ((b - a).cross(c - a).dot(a + b + c) < 0) std::swap(t[1], t[2]);
  }
}

// Two triangles per face of the quad (a, b, c, d).
void AddQuad(uint32_t a, uint32_t b, uint32_t c, uint32_t d, LocalMesh* mesh) {
  mesh->triangles.push_back({a, b, c});
  mesh->triangles.push_back({a, c, d});
}

// The largest distance between a convex inscribed tessellation and the sphere of `radius` about the origin:
// per triangle, radius minus the distance to the triangle's point closest to the centre.
double SphereGap(const LocalMesh& mesh, double radius) {
  double gap = 0;
  for (const auto& t : mesh.triangles) {
    const Vec3 c = collision::ClosestPointOnTriangle(Vec3::Zero(), mesh.vertices[t[0]], mesh.vertices[t[1]],
                                                     mesh.vertices[t[2]]);
    gap = std::max(gap, radius - c.norm());
  }
  return gap;
}

}  // namespace

// Exactly 12 triangles on the 8 corners.
LocalMesh BoxMesh(const Vec3& half) {
  LocalMesh mesh;
  for (int k = 0; k < 8; ++k) {
    mesh.vertices.emplace_back((k & 1 ? 1 : -1) * half.x(), (k & 2 ? 1 : -1) * half.y(), (k & 4 ? 1 : -1) * half.z());
  }
  for (int axis = 0; axis < 3; ++axis) {
    const int b = 1 << ((axis + 1) % 3), c = 1 << ((axis + 2) % 3);
    for (int side : {0, 1 << axis}) {
      const uint32_t base = static_cast<uint32_t>(side);
      AddQuad(base, base | b, base | b | c, base | c, &mesh);
    }
  }
  OrientOutward(&mesh);
  return mesh;
}

// A cube sphere: each cube face an n × n grid at equal angles (tan mapping keeps cells near uniform), projected
// onto the sphere. Vertices are keyed by their integer lattice point so faces share edge vertices exactly and the
// mesh is watertight. n grows until the measured gap is within kChordError.
LocalMesh SphereMesh(double radius) {
  // Cells span (π/2)/n; a triangle's circumradius is about half a cell diagonal, 1.11/n rad, and the gap r(1 − cos φ).
  int n = std::max(1, static_cast<int>(std::ceil(1.11 / std::sqrt(2 * kChordError / std::max(radius, 1e-12)))));
  for (;;) {
    LocalMesh mesh;
    std::unordered_map<uint64_t, uint32_t> index;
    const uint64_t side = static_cast<uint64_t>(n) + 1;
    auto vertex = [&](const std::array<int, 3>& l) {
      const uint64_t key = (l[0] * side + l[1]) * side + l[2];
      auto [it, fresh] = index.try_emplace(key, static_cast<uint32_t>(mesh.vertices.size()));
      if (fresh) {
        Vec3 u;
        for (int k = 0; k < 3; ++k) u[k] = std::tan((2.0 * l[k] / n - 1) * std::numbers::pi / 4);
        mesh.vertices.push_back(radius * u.normalized());
      }
      return it->second;
    };
    for (int axis = 0; axis < 3; ++axis) {
      const int b = (axis + 1) % 3, c = (axis + 2) % 3;
      for (int face : {0, n}) {
        for (int i = 0; i < n; ++i) {
          for (int j = 0; j < n; ++j) {
            std::array<int, 3> l00{}, l10{}, l11{}, l01{};
            for (auto* l : {&l00, &l10, &l11, &l01}) (*l)[axis] = face;
            l00[b] = i, l00[c] = j;
            l10[b] = i + 1, l10[c] = j;
            l11[b] = i + 1, l11[c] = j + 1;
            l01[b] = i, l01[c] = j + 1;
            AddQuad(vertex(l00), vertex(l10), vertex(l11), vertex(l01), &mesh);
          }
        }
      }
    }
    const int next = n + std::max(1, n / 8);
    if (SphereGap(mesh, radius) <= kChordError || 12 * size_t(next) * size_t(next) > kMaxTrianglesPerPrimitive) {
      OrientOutward(&mesh);
      return mesh;
    }
    n = next;
  }
}

// n side segments with sagitta r(1 − cos(π/n)) ≤ kChordError; the caps are fans, planar and exact.
LocalMesh CylinderMesh(double radius, double half_length) {
  const double c = std::clamp(1 - kChordError / std::max(radius, 1e-12), -1.0, 1.0);
  const double segments = std::ceil(std::numbers::pi / std::max(std::acos(c), 1e-9));
  const uint32_t n = static_cast<uint32_t>(std::clamp(segments, 3.0, double(kMaxTrianglesPerPrimitive / 4)));
  LocalMesh mesh;
  mesh.vertices.emplace_back(0, 0, -half_length);  // 0: bottom centre
  mesh.vertices.emplace_back(0, 0, half_length);   // 1: top centre
  for (uint32_t i = 0; i < n; ++i) {
    const double phi = 2 * std::numbers::pi * i / n;
    mesh.vertices.emplace_back(radius * std::cos(phi), radius * std::sin(phi), -half_length);  // 2 + 2i
    mesh.vertices.emplace_back(radius * std::cos(phi), radius * std::sin(phi), half_length);   // 3 + 2i
  }
  for (uint32_t i = 0; i < n; ++i) {
    const uint32_t b0 = 2 + 2 * i, t0 = b0 + 1, b1 = 2 + 2 * ((i + 1) % n), t1 = b1 + 1;
    mesh.triangles.push_back({0, b1, b0});
    mesh.triangles.push_back({1, t0, t1});
    AddQuad(b0, b1, t1, t0, &mesh);
  }
  OrientOutward(&mesh);
  return mesh;
}

}  // namespace graspsim::collision
