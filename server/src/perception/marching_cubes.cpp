#include "perception/marching_cubes.h"

#include <array>
#include <cstdint>
#include <vector>

namespace graspsim {
namespace {

// Corner c of a cell sits at offset (c & 1, c >> 1 & 1, c >> 2 & 1). Edge e runs along axis kEdgeAxis[e] from
// corner kEdgeStart[e].
constexpr std::array<int, 12> kEdgeAxis = {0, 0, 0, 0, 1, 1, 1, 1, 2, 2, 2, 2};
constexpr std::array<int, 12> kEdgeStart = {0, 2, 4, 6, 0, 1, 4, 5, 0, 1, 2, 3};

int EdgeBetween(int a, int b) {
  const int lo = a < b ? a : b, axis = (a ^ b) == 1 ? 0 : ((a ^ b) == 2 ? 1 : 2);
  for (int e = 0; e < 12; ++e) {
    if (kEdgeAxis[e] == axis && kEdgeStart[e] == lo) return e;
  }
  return -1;
}

// Two edges lie on a common face when they run along different axes and meet, or along the same axis with
// start corners one bit apart.
bool ShareFace(int a, int b) {
  const int ca = kEdgeStart[a], cb = kEdgeStart[b];
  if (kEdgeAxis[a] == kEdgeAxis[b]) return __builtin_popcount(ca ^ cb) == 1;
  const int ea = ca | 1 << kEdgeAxis[a], eb = cb | 1 << kEdgeAxis[b];
  return ca == cb || ca == eb || ea == cb || ea == eb;
}

using CaseTable = std::array<std::vector<std::array<int8_t, 3>>, 256>;

// Builds the triangles of every sign pattern from the face rule (see the header).
CaseTable BuildCaseTable() {
  // The 6 faces, corners listed counter-clockwise seen from outside the cube (around the outward normal).
  constexpr int kFaces[6][4] = {{0, 4, 6, 2}, {1, 3, 7, 5},   // x = 0, x = 1
                                {0, 1, 5, 4}, {2, 6, 7, 3},   // y = 0, y = 1
                                {0, 2, 3, 1}, {4, 5, 7, 6}};  // z = 0, z = 1
  CaseTable table;
  for (int pattern = 0; pattern < 256; ++pattern) {
    auto inside = [pattern](int corner) { return (pattern >> corner & 1) != 0; };
    std::array<int, 12> next;
    next.fill(-1);
    for (const auto& face : kFaces) {
      // Crossings in walk order; an entry (outside → inside) joins the crossing right after it, which is the
      // exit that closes off the same run of inside corners: inside corners of an ambiguous face stay apart.
      int edge[4], entering[4], count = 0;
      for (int i = 0; i < 4; ++i) {
        const int a = face[i], b = face[(i + 1) % 4];
        if (inside(a) == inside(b)) continue;
        edge[count] = EdgeBetween(a, b);
        entering[count++] = inside(b);
      }
      for (int i = 0; i < count; ++i) {
        if (entering[i]) next[edge[i]] = edge[(i + 1) % count];
      }
    }
    // Each crossed edge starts one segment and ends one: follow them into loops, fan each loop.
    std::array<bool, 12> used{};
    for (int start = 0; start < 12; ++start) {
      if (next[start] < 0 || used[start]) continue;
      std::vector<int> loop;
      for (int e = start; !used[e]; e = next[e]) {
        used[e] = true;
        loop.push_back(e);
      }
      // Fan from a vertex whose diagonals never join two crossings of one face: such a diagonal lies in the
      // face, where the neighbouring cell may draw the same one, and the edge would belong to four triangles.
      // (Every loop of the 256 patterns has such a vertex; MarchingCubesTest checks the result is manifold.)
      const size_t m = loop.size();
      size_t apex = 0;
      for (size_t start = 0; start < m; ++start) {
        bool clean = true;
        for (size_t i = 2; i + 1 < m; ++i) clean = clean && !ShareFace(loop[start], loop[(start + i) % m]);
        if (clean) {
          apex = start;
          break;
        }
      }
      for (size_t i = 1; i + 1 < m; ++i) {
        table[pattern].push_back(
            {int8_t(loop[apex]), int8_t(loop[(apex + i) % m]), int8_t(loop[(apex + i + 1) % m])});
      }
    }
  }
  return table;
}

const CaseTable& Cases() {
  static const CaseTable table = BuildCaseTable();
  return table;
}

}  // namespace

TriangleMesh ExtractIsoSurface(const GridSamples& grid, float iso) {
  TriangleMesh mesh;
  const int nx = grid.nodes.x(), ny = grid.nodes.y(), nz = grid.nodes.z();
  if (nx < 2 || ny < 2 || nz < 2) return mesh;
  const CaseTable& cases = Cases();
  auto value = [&](int i, int j, int k) { return grid.values[(int64_t(k) * ny + j) * nx + i]; };
  // Vertex of each crossed grid edge, by the edge's lower node and axis: x/y edges of the node layers k and k + 1
  // and the z edges between them, so memory stays at two layers however fine the grid.
  const int64_t layer = int64_t(nx) * ny;
  std::vector<int32_t> plane_edges[2] = {std::vector<int32_t>(2 * layer, -1), std::vector<int32_t>(2 * layer, -1)};
  std::vector<int32_t> z_edges(layer, -1);
  auto vertex = [&](int i, int j, int k, int axis, int k0) -> uint32_t {
    int32_t& slot = axis == 2 ? z_edges[int64_t(j) * nx + i]
                              : plane_edges[k - k0][(int64_t(j) * nx + i) * 2 + axis];
    if (slot >= 0) return uint32_t(slot);
    const int i1 = i + (axis == 0), j1 = j + (axis == 1), k1 = k + (axis == 2);
    const float a = value(i, j, k), b = value(i1, j1, k1);
    const double t = double(iso - a) / double(b - a);  // a < iso ≤ b or the reverse: b ≠ a
    const Vec3 p0 = grid.origin + grid.spacing * Vec3(i, j, k);
    Vec3 p = p0;
    p[axis] += t * grid.spacing;
    slot = int32_t(mesh.vertices.size());
    mesh.vertices.push_back(p.cast<float>());
    return uint32_t(slot);
  };
  // Inside flags once per node (a pass that vectorises), then each cell's pattern from eight bytes: most cells
  // are all in or all out and cost only that.
  std::vector<uint8_t> inside(layer * nz);
  for (int64_t i = 0; i < layer * nz; ++i) inside[i] = grid.values[i] < iso;
  for (int k = 0; k + 1 < nz; ++k) {
    for (int j = 0; j + 1 < ny; ++j) {
      const uint8_t* s00 = inside.data() + (int64_t(k) * ny + j) * nx;  // corners (·, 0, 0)
      const uint8_t *s01 = s00 + nx, *s10 = s00 + layer, *s11 = s10 + nx;
      for (int i = 0; i + 1 < nx; ++i) {
        const int pattern = s00[i] | s00[i + 1] << 1 | s01[i] << 2 | s01[i + 1] << 3 | s10[i] << 4 |
                            s10[i + 1] << 5 | s11[i] << 6 | s11[i + 1] << 7;
        if (pattern == 0 || pattern == 255) continue;
        for (const auto& tri : cases[pattern]) {
          std::array<uint32_t, 3> t;
          for (int v = 0; v < 3; ++v) {
            const int e = tri[v], c = kEdgeStart[e];
            t[v] = vertex(i + (c & 1), j + (c >> 1 & 1), k + (c >> 2 & 1), kEdgeAxis[e], k);
          }
          mesh.triangles.push_back(t);
        }
      }
    }
    // Layer k + 1 becomes the lower layer of the next slab; its z edges are new.
    std::swap(plane_edges[0], plane_edges[1]);
    std::fill(plane_edges[1].begin(), plane_edges[1].end(), -1);
    std::fill(z_edges.begin(), z_edges.end(), -1);
  }
  return mesh;
}

}  // namespace graspsim
