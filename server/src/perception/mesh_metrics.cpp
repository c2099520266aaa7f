#include "perception/mesh_metrics.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <unordered_map>

namespace graspsim {
namespace {

Vec3 Vertex(const TriangleMesh& mesh, uint32_t i) { return mesh.vertices[i].cast<double>(); }

// The point of triangle abc nearest to p: p projected into the triangle's plane if that lands inside, else the
// nearest point of the nearest edge (checked on all three: simple, and exact).
Vec3 ClosestOnTriangle(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c) {
  const Vec3 n = (b - a).cross(c - a);
  const double nn = n.squaredNorm();
  if (nn > 0) {
    const Vec3 q = p - n * (n.dot(p - a) / nn);
    // Inside when q is on the inner side of all three edges.
    if (n.dot((b - a).cross(q - a)) >= 0 && n.dot((c - b).cross(q - b)) >= 0 && n.dot((a - c).cross(q - c)) >= 0) {
      return q;
    }
  }
  auto on_segment = [&p](const Vec3& s, const Vec3& e) {
    const Vec3 d = e - s;
    const double dd = d.squaredNorm();
    const double t = dd > 0 ? std::clamp(d.dot(p - s) / dd, 0.0, 1.0) : 0.0;
    return Vec3(s + t * d);
  };
  Vec3 best = on_segment(a, b);
  for (const Vec3& candidate : {on_segment(b, c), on_segment(c, a)}) {
    if ((candidate - p).squaredNorm() < (best - p).squaredNorm()) best = candidate;
  }
  return best;
}

}  // namespace

EdgeCounts CountEdges(const TriangleMesh& mesh) {
  // Per undirected edge: uses, and the net direction (+1 for low→high, −1 for high→low).
  std::unordered_map<uint64_t, std::pair<int, int>> edges;
  edges.reserve(mesh.triangles.size() * 2);
  for (const auto& t : mesh.triangles) {
    for (int e = 0; e < 3; ++e) {
      const uint32_t a = t[e], b = t[(e + 1) % 3];
      const uint64_t key = (uint64_t(std::min(a, b)) << 32) | std::max(a, b);
      auto& entry = edges[key];
      ++entry.first;
      entry.second += a < b ? 1 : -1;
    }
  }
  EdgeCounts counts;
  counts.edges = edges.size();
  for (const auto& [key, entry] : edges) {
    if (entry.first == 1) ++counts.boundary;
    if (entry.first >= 3) ++counts.non_manifold;
    if (entry.first == 2 && entry.second != 0) ++counts.misoriented;
  }
  return counts;
}

double EnclosedVolume(const TriangleMesh& mesh) {
  double six_volume = 0;
  for (const auto& t : mesh.triangles) {
    six_volume += Vertex(mesh, t[0]).dot(Vertex(mesh, t[1]).cross(Vertex(mesh, t[2])));
  }
  return six_volume / 6;
}

std::vector<Vec3> SampleSurface(const TriangleMesh& mesh, size_t count, uint64_t seed) {
  std::vector<double> cumulative(mesh.triangles.size());
  double total = 0;
  for (size_t i = 0; i < mesh.triangles.size(); ++i) {
    const auto& t = mesh.triangles[i];
    total += 0.5 * (Vertex(mesh, t[1]) - Vertex(mesh, t[0])).cross(Vertex(mesh, t[2]) - Vertex(mesh, t[0])).norm();
    cumulative[i] = total;
  }
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::vector<Vec3> out;
  out.reserve(count);
  for (size_t s = 0; s < count; ++s) {
    const double pick = unit(rng) * total;
    const size_t i = std::min(size_t(std::upper_bound(cumulative.begin(), cumulative.end(), pick) - cumulative.begin()),
                              cumulative.size() - 1);
    double u = unit(rng), v = unit(rng);
    if (u + v > 1) {  // fold the unit square's far half back onto the triangle: uniform in the triangle
      u = 1 - u;
      v = 1 - v;
    }
    const auto& t = mesh.triangles[i];
    const Vec3 a = Vertex(mesh, t[0]);
    out.push_back(a + u * (Vertex(mesh, t[1]) - a) + v * (Vertex(mesh, t[2]) - a));
  }
  return out;
}

MeshDistance::MeshDistance(const TriangleMesh& mesh) : mesh_(mesh) {
  Vec3 lo = Vec3::Constant(std::numeric_limits<double>::max()), hi = -lo;
  double edge_sum = 0;
  for (const auto& t : mesh.triangles) {
    for (int e = 0; e < 3; ++e) {
      lo = lo.cwiseMin(Vertex(mesh, t[e]));
      hi = hi.cwiseMax(Vertex(mesh, t[e]));
      edge_sum += (Vertex(mesh, t[e]) - Vertex(mesh, t[(e + 1) % 3])).norm();
    }
  }
  origin_ = lo;
  // Cells about two mean edges wide hold a few triangles each on a surface mesh.
  cell_size_ = std::max(2 * edge_sum / (3.0 * std::max<size_t>(mesh.triangles.size(), 1)), 1e-9);
  for (;;) {
    const Vec3 extent = (hi - lo) / cell_size_;
    dims_ = Eigen::Vector3i(int(extent.x()) + 1, int(extent.y()) + 1, int(extent.z()) + 1);
    if (double(dims_[0]) * dims_[1] * dims_[2] <= 8.0 * double(mesh.triangles.size()) + 64) break;
    cell_size_ *= 1.5;
  }
  const int64_t cells = int64_t(dims_[0]) * dims_[1] * dims_[2];
  cell_start_.assign(cells + 1, 0);
  // Two passes over the triangles' bounding boxes: count, then fill.
  for (int pass = 0; pass < 2; ++pass) {
    std::vector<uint32_t> fill;
    if (pass == 1) {
      for (int64_t c = 0; c < cells; ++c) cell_start_[c + 1] += cell_start_[c];
      triangles_.resize(cell_start_[cells]);
      fill.assign(cell_start_.begin(), cell_start_.end() - 1);
    }
    for (uint32_t i = 0; i < mesh.triangles.size(); ++i) {
      const auto& t = mesh.triangles[i];
      Vec3 tlo = Vertex(mesh, t[0]), thi = tlo;
      for (int e = 1; e < 3; ++e) {
        tlo = tlo.cwiseMin(Vertex(mesh, t[e]));
        thi = thi.cwiseMax(Vertex(mesh, t[e]));
      }
      const Eigen::Vector3i a = CellOf(tlo), b = CellOf(thi);
      for (int z = a.z(); z <= b.z(); ++z) {
        for (int y = a.y(); y <= b.y(); ++y) {
          for (int x = a.x(); x <= b.x(); ++x) {
            if (pass == 0) ++cell_start_[CellIndex(x, y, z) + 1];
            else triangles_[fill[CellIndex(x, y, z)]++] = i;
          }
        }
      }
    }
  }
}

Eigen::Vector3i MeshDistance::CellOf(const Vec3& p) const {
  Eigen::Vector3i c;
  for (int a = 0; a < 3; ++a) c[a] = std::clamp(int(std::floor((p[a] - origin_[a]) / cell_size_)), 0, dims_[a] - 1);
  return c;
}

double MeshDistance::Distance(const Vec3& point) const {
  double best = std::numeric_limits<double>::infinity();
  const Eigen::Vector3i center = CellOf(point);
  // Ring r + 1's cells are at least r cells away along some axis, and a point outside the grid is `offset` away
  // from all of them: no closer triangle remains once the best is within hypot(offset, r cells).
  Vec3 outside = Vec3::Zero();
  for (int a = 0; a < 3; ++a) {
    outside[a] = std::max({origin_[a] - point[a], point[a] - (origin_[a] + dims_[a] * cell_size_), 0.0});
  }
  const double offset = outside.norm();
  for (int ring = 0; ring <= dims_.maxCoeff(); ++ring) {
    const Eigen::Vector3i lo = (center.array() - ring).max(0), hi = (center.array() + ring).min(dims_.array() - 1);
    for (int z = lo.z(); z <= hi.z(); ++z) {
      for (int y = lo.y(); y <= hi.y(); ++y) {
        for (int x = lo.x(); x <= hi.x(); ++x) {
          if (std::max({std::abs(x - center.x()), std::abs(y - center.y()), std::abs(z - center.z())}) != ring) continue;
          const int64_t c = CellIndex(x, y, z);
          for (uint32_t j = cell_start_[c]; j < cell_start_[c + 1]; ++j) {
            const auto& t = mesh_.triangles[triangles_[j]];
            const Vec3 q = ClosestOnTriangle(point, Vertex(mesh_, t[0]), Vertex(mesh_, t[1]), Vertex(mesh_, t[2]));
            best = std::min(best, (q - point).squaredNorm());
          }
        }
      }
    }
    if (best <= offset * offset + std::pow(ring * cell_size_, 2)) break;
  }
  return std::sqrt(best);
}

}  // namespace graspsim
