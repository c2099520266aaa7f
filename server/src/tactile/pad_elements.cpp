// A tactile pad's sensing elements on its flat or wrapped grid (see pad_elements.h).
#include "tactile/pad_elements.h"

#include <algorithm>
#include <cmath>
#include <tuple>

namespace graspsim {

Vec3 PadSurfacePoint(const TactileArraySpec& pad, double x, double y) {
  // Wrapping keeps arc length: x becomes the angle x / R on a circle of radius R whose top touches z = 0.
  auto wrap = [](double radius, double u, double* along, double* drop) {
    if (!(radius > 0)) {
      *along = u;
      return;
    }
    *along = radius * std::sin(u / radius);
    *drop += radius * (1 - std::cos(u / radius));
  };
  Vec3 p(0, 0, 0);
  double drop = 0;
  wrap(pad.bend_radius_x, x, &p.x(), &drop);
  wrap(pad.bend_radius_y, y, &p.y(), &drop);
  p.z() = -drop;
  return p;
}

std::vector<PadElement> MakePadElements(const TactileArraySpec& pad) {
  const uint32_t s = std::max(pad.subdivision, 1u);
  const uint32_t rows = pad.rows * s, cols = pad.cols * s;
  const double cell = pad.pitch / s, x0 = -0.5 * pad.cols * pad.pitch, y0 = -0.5 * pad.rows * pad.pitch;
  auto unit_normal = [](const Vec3& a, const Vec3& b, const Vec3& c) {
    const Vec3 n = (b - a).cross(c - a);
    return n.squaredNorm() > 0 ? Vec3(n.normalized()) : Vec3(Vec3::Zero());
  };
  std::vector<PadElement> elements;
  if (pad.placement == PadElementPlacement::kFaceCentres) {
    // Vertices at the cell corners; per cell two counter-clockwise triangles (seen from +z), each an element at
    // its centroid with its own normal.
    auto corner = [&](uint32_t r, uint32_t c) { return PadSurfacePoint(pad, x0 + c * cell, y0 + r * cell); };
    elements.reserve(size_t(rows) * cols * 2);
    for (uint32_t r = 0; r < rows; ++r) {
      for (uint32_t c = 0; c < cols; ++c) {
        const Vec3 v00 = corner(r, c), v01 = corner(r, c + 1), v10 = corner(r + 1, c), v11 = corner(r + 1, c + 1);
        for (const auto& [a, b, d] : {std::tuple{v00, v01, v11}, std::tuple{v00, v11, v10}}) {
          PadElement& e = elements.emplace_back();
          e.position = (a + b + d) / 3;
          e.normal = unit_normal(a, b, d);
          if (e.normal.squaredNorm() == 0) e.normal = Vec3::UnitZ();
          e.row = r / s;
          e.col = c / s;
        }
      }
    }
    return elements;
  }
  elements.resize(size_t(rows) * cols);
  for (uint32_t r = 0; r < rows; ++r) {
    for (uint32_t c = 0; c < cols; ++c) {
      PadElement& e = elements[size_t(r) * cols + c];
      e.position = PadSurfacePoint(pad, x0 + (c + 0.5) * cell, y0 + (r + 0.5) * cell);
      std::tie(e.row, e.col) = ElementTexel(pad, r * cols + c);
      e.normal = Vec3::Zero();
    }
  }
  // The elements are the vertices of a triangle grid (counter-clockwise seen from +z); each vertex normal is the
  // normalised sum of its faces' unit normals.
  auto add_face = [&](size_t a, size_t b, size_t c) {
    const Vec3 n = unit_normal(elements[a].position, elements[b].position, elements[c].position);
    for (size_t v : {a, b, c}) elements[v].normal += n;
  };
  for (uint32_t r = 0; r + 1 < rows; ++r) {
    for (uint32_t c = 0; c + 1 < cols; ++c) {
      const size_t v00 = size_t(r) * cols + c, v01 = v00 + 1, v10 = v00 + cols, v11 = v10 + 1;
      add_face(v00, v01, v11);
      add_face(v00, v11, v10);
    }
  }
  // A single row or column has no faces: such a strip faces +z.
  for (PadElement& e : elements) e.normal = e.normal.squaredNorm() > 0 ? Vec3(e.normal.normalized()) : Vec3::UnitZ();
  return elements;
}

}  // namespace graspsim
