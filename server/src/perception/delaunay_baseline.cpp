#include "perception/delaunay_baseline.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <random>
#include <string>
#include <utility>

#include <opencv2/imgproc.hpp>

#include "core/error.h"
#include "core/format.h"

namespace graspsim {
namespace {

// `count` distinct indices of `n`, by a seeded partial Fisher–Yates shuffle (all of them when count ≥ n).
std::vector<uint32_t> SampleIndices(size_t n, size_t count, uint64_t seed) {
  std::vector<uint32_t> order(n);
  for (uint32_t i = 0; i < n; ++i) order[i] = i;
  if (count >= n) return order;
  std::mt19937_64 random(seed);
  for (size_t i = 0; i < count; ++i) std::swap(order[i], order[i + random() % (n - i)]);
  order.resize(count);
  std::sort(order.begin(), order.end());
  return order;
}

}  // namespace

TriangleMesh DelaunayBaseline(const std::vector<Vec3>& points, const Pose& camera_pose, const DelaunayParams& params) {
  if (params.samples < 3 || params.samples > 100000) {
    ThrowInvalidArgument("delaunay.samples: " + std::to_string(params.samples) + " is outside 3..100000");
  }
  if (!(params.max_edge_factor > 1)) {
    ThrowInvalidArgument("delaunay.max_edge_factor: " + FormatNumber(params.max_edge_factor) + " must exceed 1");
  }
  if (points.size() < 3) ThrowInvalidArgument("points: " + std::to_string(points.size()) + " points; need 3");
  const std::vector<uint32_t> chosen = SampleIndices(points.size(), size_t(params.samples), params.seed);

  // Project onto the image plane (x/z, y/z), scaled to ~1000 units across for Subdiv2D's float coordinates.
  const Pose to_camera = camera_pose.Inverse();
  std::vector<cv::Point2f> image(chosen.size());
  double lo_x = 1e300, lo_y = 1e300, hi_x = -1e300, hi_y = -1e300;
  std::vector<Eigen::Vector2d> projected(chosen.size());
  for (size_t i = 0; i < chosen.size(); ++i) {
    const Vec3 c = to_camera * points[chosen[i]];
    projected[i] = Eigen::Vector2d(c.x() / std::max(c.z(), 1e-9), c.y() / std::max(c.z(), 1e-9));
    lo_x = std::min(lo_x, projected[i].x());
    hi_x = std::max(hi_x, projected[i].x());
    lo_y = std::min(lo_y, projected[i].y());
    hi_y = std::max(hi_y, projected[i].y());
  }
  const double scale = 1000.0 / std::max({hi_x - lo_x, hi_y - lo_y, 1e-12});
  cv::Subdiv2D subdiv(cv::Rect(-2, -2, int(std::ceil(scale * (hi_x - lo_x))) + 5,
                               int(std::ceil(scale * (hi_y - lo_y))) + 5));
  std::map<int, uint32_t> vertex_to_point;  // Subdiv2D's vertex id → index into `chosen`
  for (size_t i = 0; i < chosen.size(); ++i) {
    image[i] = cv::Point2f(float(scale * (projected[i].x() - lo_x)), float(scale * (projected[i].y() - lo_y)));
    vertex_to_point.try_emplace(subdiv.insert(image[i]), uint32_t(i));
  }
  std::vector<cv::Vec6f> list;
  subdiv.getTriangleList(list);

  // Triangles by sample index, facing the camera; edges longer than max_edge_factor × the median dropped.
  std::vector<std::array<uint32_t, 3>> sheet;
  std::vector<double> edges;
  for (const cv::Vec6f& t : list) {
    std::array<uint32_t, 3> tri;
    bool known = true;
    for (int c = 0; c < 3; ++c) {
      const int vertex = subdiv.findNearest(cv::Point2f(t[2 * c], t[2 * c + 1]));
      auto it = vertex_to_point.find(vertex);
      if (it == vertex_to_point.end()) {
        known = false;
      } else {
        tri[c] = it->second;
      }
    }
    if (!known || tri[0] == tri[1] || tri[1] == tri[2] || tri[0] == tri[2]) continue;
    const Vec3 &a = points[chosen[tri[0]]], &b = points[chosen[tri[1]]], &c = points[chosen[tri[2]]];
    if ((b - a).cross(c - a).dot(camera_pose.position - a) < 0) std::swap(tri[1], tri[2]);
    sheet.push_back(tri);
    edges.insert(edges.end(), {(b - a).norm(), (c - b).norm(), (a - c).norm()});
  }
  if (sheet.empty()) ThrowInvalidArgument("points: their projection has no triangle (all on a line?)");
  std::nth_element(edges.begin(), edges.begin() + edges.size() / 2, edges.end());
  const double max_edge = params.max_edge_factor * edges[edges.size() / 2];
  std::vector<std::array<uint32_t, 3>> kept;
  for (const auto& tri : sheet) {
    bool short_edges = true;
    for (int e = 0; e < 3; ++e) {
      short_edges &= (points[chosen[tri[e]]] - points[chosen[tri[(e + 1) % 3]]]).norm() <= max_edge;
    }
    if (short_edges) kept.push_back(tri);
  }
  if (kept.empty()) ThrowInvalidArgument("points: every Delaunay triangle has an over-long edge");

  // Closed shell: the front sheet, its reversed copy on duplicated vertices (index + n), and along each boundary
  // edge a → b (used by one front triangle) the zero-area quad (b, a, a'), (b, a', b') joining them.
  const uint32_t n = uint32_t(chosen.size());
  TriangleMesh mesh;
  mesh.vertices.reserve(2 * n);
  for (int copy = 0; copy < 2; ++copy) {
    for (uint32_t i = 0; i < n; ++i) mesh.vertices.push_back(points[chosen[i]].cast<float>());
  }
  std::map<std::pair<uint32_t, uint32_t>, int> directed;
  for (const auto& tri : kept) {
    mesh.triangles.push_back(tri);
    mesh.triangles.push_back({tri[0] + n, tri[2] + n, tri[1] + n});
    for (int e = 0; e < 3; ++e) ++directed[{tri[e], tri[(e + 1) % 3]}];
  }
  for (const auto& [edge, count] : directed) {
    if (directed.count({edge.second, edge.first})) continue;  // interior
    const auto [a, b] = edge;
    mesh.triangles.push_back({b, a, a + n});
    mesh.triangles.push_back({b, a + n, b + n});
  }
  return mesh;
}

}  // namespace graspsim
