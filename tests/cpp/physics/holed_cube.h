// The test object of PAPERS.md part B experiment 5 (shape recognition): a cube with a recessed pocket in its +z
// face and another in its −z face, each pocket a union of axis-aligned rectangles of one depth (a cross, a
// square). Header-only: the test binary compiles only *_test.cpp files.
//
// The mesh lives on a rectilinear grid: its x and y lines are the cube's edges and every pocket rectangle's edges,
// so every grid cell is wholly solid or wholly pocket on each face. Each cell is a column from its bottom (the −z
// face or the square pocket's floor) to its top (the +z face or the cross pocket's floor); the surface is the
// columns' tops and bottoms plus a wall wherever a column's z-range pokes out beyond its neighbour's (or beyond
// the cube). Vertices are keyed by (grid x, grid y, z level), so neighbours share them exactly, and every edge
// spans one grid interval, so there are no T-junctions: the mesh is closed, with every edge in exactly two
// triangles, provided no grid vertex is a saddle (two diagonal pocket cells, two diagonal solid cells), which
// unions of rectangles like a cross or a square never produce. Triangles are counter-clockwise seen from outside.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <map>
#include <tuple>
#include <vector>

#include "core/math.h"
#include "core/mesh.h"
#include "world/model.h"

namespace graspsim::test_objects {

// An axis-aligned rectangle in the cube's body (x, y), m.
struct Rect {
  double x0 = 0, y0 = 0, x1 = 0, y1 = 0;
  bool Contains(double x, double y) const { return x > x0 && x < x1 && y > y0 && y < y1; }
};

struct HoledCube {
  double side = 0.05;                // m, edge length; the cube is centred on the body origin
  double depth = 0.005;              // m, both pockets
  std::vector<Rect> top_pocket;      // in the +z face (a union of rectangles), body (x, y)
  std::vector<Rect> bottom_pocket;   // in the −z face, body (x, y)

  static bool InPocket(const std::vector<Rect>& pocket, double x, double y) {
    return std::any_of(pocket.begin(), pocket.end(), [&](const Rect& r) { return r.Contains(x, y); });
  }
};

// A plus sign centred on the face: two arms `length` long and `width` wide, along x and along y.
inline std::vector<Rect> CrossPocket(double length, double width) {
  return {{-length / 2, -width / 2, length / 2, width / 2}, {-width / 2, -length / 2, width / 2, length / 2}};
}

// A square of edge `side` centred on the face.
inline std::vector<Rect> SquarePocket(double side) { return {{-side / 2, -side / 2, side / 2, side / 2}}; }

// The experiment's object: a 5 cm cube, a cross (arms 40 mm × 8 mm) 5 mm deep in the +z face and a 15 mm square
// 5 mm deep in the −z face.
inline HoledCube ExperimentCube() {
  HoledCube cube;
  cube.top_pocket = CrossPocket(0.04, 0.008);
  cube.bottom_pocket = SquarePocket(0.015);
  return cube;
}

namespace holed_cube_detail {

// The grid lines along one axis: the cube's edges and the pockets' edges inside it, sorted and unique.
inline std::vector<double> GridLines(const HoledCube& cube, bool along_x) {
  const double h = cube.side / 2;
  std::vector<double> lines = {-h, h};
  for (const auto* pocket : {&cube.top_pocket, &cube.bottom_pocket}) {
    for (const Rect& r : *pocket) {
      for (double v : along_x ? std::array{r.x0, r.x1} : std::array{r.y0, r.y1}) {
        if (v > -h && v < h) lines.push_back(v);
      }
    }
  }
  std::sort(lines.begin(), lines.end());
  lines.erase(std::unique(lines.begin(), lines.end()), lines.end());
  return lines;
}

// Per grid cell: the column's z-range as level indices (0: −side/2, 1: −side/2 + depth, 2: side/2 − depth,
// 3: side/2).
struct Columns {
  std::vector<double> xs, ys;
  std::vector<std::array<int, 2>> range;  // (bottom level, top level), row-major over (i along x, j along y)
  int nx = 0, ny = 0;
  const std::array<int, 2>* At(int i, int j) const {
    if (i < 0 || j < 0 || i >= nx || j >= ny) return nullptr;  // outside the cube
    return &range[size_t(j) * nx + i];
  }
};

inline Columns MakeColumns(const HoledCube& cube) {
  Columns c;
  c.xs = GridLines(cube, true);
  c.ys = GridLines(cube, false);
  c.nx = static_cast<int>(c.xs.size()) - 1;
  c.ny = static_cast<int>(c.ys.size()) - 1;
  for (int j = 0; j < c.ny; ++j) {
    for (int i = 0; i < c.nx; ++i) {
      const double x = (c.xs[i] + c.xs[i + 1]) / 2, y = (c.ys[j] + c.ys[j + 1]) / 2;
      c.range.push_back({HoledCube::InPocket(cube.bottom_pocket, x, y) ? 1 : 0,
                         HoledCube::InPocket(cube.top_pocket, x, y) ? 2 : 3});
    }
  }
  return c;
}

inline std::array<double, 4> Levels(const HoledCube& cube) {
  const double h = cube.side / 2;
  return {-h, -h + cube.depth, h - cube.depth, h};
}

}  // namespace holed_cube_detail

// The closed triangle mesh of `cube`, in its body frame (centred on the origin).
inline TriangleMesh HoledCubeMesh(const HoledCube& cube) {
  using namespace holed_cube_detail;
  const Columns c = MakeColumns(cube);
  const std::array<double, 4> z = Levels(cube);
  TriangleMesh mesh;
  std::map<std::tuple<int, int, int>, uint32_t> index;
  auto vertex = [&](int i, int j, int level) {
    auto [it, fresh] = index.try_emplace({i, j, level}, static_cast<uint32_t>(mesh.vertices.size()));
    if (fresh) mesh.vertices.emplace_back(float(c.xs[i]), float(c.ys[j]), float(z[level]));
    return it->second;
  };
  // Two triangles on the planar quad a b c d (in order around it), turned so they face along `outward`.
  auto quad = [&](std::array<uint32_t, 4> q, const Vec3& outward) {
    const Vec3 a = mesh.vertices[q[0]].cast<double>(), b = mesh.vertices[q[1]].cast<double>(),
               d = mesh.vertices[q[3]].cast<double>();
    if ((b - a).cross(d - a).dot(outward) < 0) std::swap(q[1], q[3]);
    mesh.triangles.push_back({q[0], q[1], q[2]});
    mesh.triangles.push_back({q[0], q[2], q[3]});
  };
  for (int j = 0; j < c.ny; ++j) {
    for (int i = 0; i < c.nx; ++i) {
      const auto [bottom, top] = *c.At(i, j);
      quad({vertex(i, j, top), vertex(i + 1, j, top), vertex(i + 1, j + 1, top), vertex(i, j + 1, top)},
           Vec3::UnitZ());
      quad({vertex(i, j, bottom), vertex(i + 1, j, bottom), vertex(i + 1, j + 1, bottom), vertex(i, j + 1, bottom)},
           -Vec3::UnitZ());
      // Walls toward the four neighbours: where this column reaches below or above the neighbour's range.
      struct Side {
        int di, dj;
        std::array<int, 2> a, b;  // the shared cell edge's grid vertices, (i, j)
      };
      const std::array<Side, 4> sides = {{{1, 0, {i + 1, j}, {i + 1, j + 1}},
                                          {-1, 0, {i, j}, {i, j + 1}},
                                          {0, 1, {i, j + 1}, {i + 1, j + 1}},
                                          {0, -1, {i, j}, {i + 1, j}}}};
      for (const Side& s : sides) {
        const std::array<int, 2>* other = c.At(i + s.di, j + s.dj);
        std::vector<std::array<int, 2>> spans;  // level ranges of wall
        if (other == nullptr) {
          spans.push_back({bottom, top});
        } else {
          if (bottom < (*other)[0]) spans.push_back({bottom, (*other)[0]});
          if ((*other)[1] < top) spans.push_back({(*other)[1], top});
        }
        for (const auto& [lo, hi] : spans) {
          quad({vertex(s.a[0], s.a[1], lo), vertex(s.b[0], s.b[1], lo), vertex(s.b[0], s.b[1], hi),
                vertex(s.a[0], s.a[1], hi)},
               Vec3(s.di, s.dj, 0));
        }
      }
    }
  }
  return mesh;
}

// Mass properties of `cube` filled with `density` (kg/m³), exact: the sum of its columns (boxes), in its body
// frame (inertia about the centre of mass).
inline Inertial HoledCubeInertial(const HoledCube& cube, double density) {
  using namespace holed_cube_detail;
  const Columns c = MakeColumns(cube);
  const std::array<double, 4> z = Levels(cube);
  struct Box {
    double mass;
    Vec3 centre, size;
  };
  std::vector<Box> boxes;
  Inertial inertial;
  for (int j = 0; j < c.ny; ++j) {
    for (int i = 0; i < c.nx; ++i) {
      const auto [bottom, top] = *c.At(i, j);
      const Vec3 lo(c.xs[i], c.ys[j], z[bottom]), hi(c.xs[i + 1], c.ys[j + 1], z[top]);
      const Vec3 size = hi - lo;
      const double mass = density * size.prod();
      boxes.push_back({mass, (lo + hi) / 2, size});
      inertial.mass += mass;
      inertial.center_of_mass += mass * boxes.back().centre;
    }
  }
  inertial.center_of_mass /= inertial.mass;
  for (const Box& b : boxes) {
    const Vec3 s2 = b.size.cwiseProduct(b.size);
    const Vec3 r = b.centre - inertial.center_of_mass;
    inertial.inertia += Vec3(s2.y() + s2.z(), s2.x() + s2.z(), s2.x() + s2.y()).asDiagonal() * (b.mass / 12);
    inertial.inertia += b.mass * (r.squaredNorm() * Mat3::Identity() - r * r.transpose());  // parallel axes
  }
  return inertial;
}

// Is the body point (x, y) on face `top` (+z) solid, i.e. on the face and not over its pocket?
inline bool FaceIsSolid(const HoledCube& cube, bool top, double x, double y) {
  const double h = cube.side / 2;
  if (std::abs(x) >= h || std::abs(y) >= h) return false;
  return !HoledCube::InPocket(top ? cube.top_pocket : cube.bottom_pocket, x, y);
}

}  // namespace graspsim::test_objects
