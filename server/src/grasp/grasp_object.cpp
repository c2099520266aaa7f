#include "grasp/grasp_object.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <utility>

#include <Eigen/Eigenvalues>

namespace graspsim::grasp {
namespace {

// A vertex is sharp when two of its faces' normals differ by more than this: 20 deg. Below it, the hand's
// surface samples (a few mm apart) cannot straddle a bump deep enough to matter.
const double kSharpCos = std::cos(20.0 * 3.14159265358979 / 180);
// At most this many sharp vertices are swept (a scanned mesh has many noisy ones, and each costs a test per link
// and closing step); beyond it, every k-th, so the bound of simulate.h then holds only for the kept ones.
constexpr size_t kMaxSharp = 512;
// Sharp vertices per cluster (GraspObject::sharp_clusters): a sweep tests one ball for this many.
constexpr size_t kClusterSize = 16;

}  // namespace

GraspObject::GraspObject(std::shared_ptr<const TriangleMesh> mesh, std::vector<ObstacleBox> obstacles)
    : mesh_(std::move(mesh)), obstacles_(std::move(obstacles)) {
  const TriangleMesh& m = *mesh_;
  bvh_ = std::make_unique<collision::EmbreeScene>(m, RTC_BUILD_QUALITY_HIGH);  // built once, cast millions of times
  lo_ = Vec3::Constant(std::numeric_limits<double>::infinity());
  hi_ = -lo_;
  for (const auto& v : m.vertices) {
    lo_ = lo_.cwiseMin(v.cast<double>());
    hi_ = hi_.cwiseMax(v.cast<double>());
  }
  // Area-weighted centroid and second moment of the surface (exact for flat triangles).
  double area = 0;
  Vec3 sum = Vec3::Zero();
  Mat3 second = Mat3::Zero();
  face_normals_.reserve(m.triangles.size());
  for (const auto& t : m.triangles) {
    const Vec3 a = m.vertices[t[0]].cast<double>(), b = m.vertices[t[1]].cast<double>(), c = m.vertices[t[2]].cast<double>();
    const Vec3 n = (b - a).cross(c - a);
    const double twice = n.norm();
    face_normals_.push_back(twice > 0 ? Vec3(n / twice) : Vec3::Zero());
    const double w = 0.5 * twice;
    area += w;
    sum += w * (a + b + c) / 3;
    second += w / 12 * (a * a.transpose() + b * b.transpose() + c * c.transpose() + (a + b + c) * (a + b + c).transpose());
  }
  centroid_ = area > 0 ? Vec3(sum / area) : Vec3(0.5 * (lo_ + hi_));
  if (area > 0) {
    const Mat3 covariance = second / area - centroid_ * centroid_.transpose();
    Eigen::SelfAdjointEigenSolver<Mat3> solver(covariance);
    // Eigen sorts ascending; columns major, middle, minor, right-handed.
    axes_.col(0) = solver.eigenvectors().col(2);
    axes_.col(1) = solver.eigenvectors().col(1);
    axes_.col(2) = axes_.col(0).cross(axes_.col(1));
  }
  for (const auto& v : m.vertices) length_ = std::max(length_, (v.cast<double>() - centroid_).norm());
  length_ = std::max(length_, 1e-6);

  // Sharp vertices: the largest normal angle among the faces around each vertex.
  std::vector<Vec3> first(m.vertices.size(), Vec3::Zero());
  std::vector<bool> sharp(m.vertices.size(), false);
  for (size_t f = 0; f < m.triangles.size(); ++f) {
    const Vec3& n = face_normals_[f];
    if (n.isZero()) continue;
    for (uint32_t v : m.triangles[f]) {
      if (first[v].isZero()) {
        first[v] = n;
      } else if (first[v].dot(n) < kSharpCos) {
        sharp[v] = true;
      }
    }
  }
  // A second pass catches a vertex whose first face was the odd one out only against later faces.
  for (size_t f = 0; f < m.triangles.size(); ++f) {
    for (uint32_t v : m.triangles[f]) {
      if (!face_normals_[f].isZero() && first[v].dot(face_normals_[f]) < kSharpCos) sharp[v] = true;
    }
  }
  // Only convex sharp vertices can poke into a hand face: the vertex must stand out of the plane through its
  // neighbours' centroid along its (area-weighted) normal. Concave creases are reached by the hand's samples.
  std::vector<Vec3> normal_sum(m.vertices.size(), Vec3::Zero()), neighbour_sum(m.vertices.size(), Vec3::Zero());
  std::vector<int> neighbours(m.vertices.size(), 0);
  for (size_t f = 0; f < m.triangles.size(); ++f) {
    const auto& t = m.triangles[f];
    for (int k = 0; k < 3; ++k) {
      normal_sum[t[k]] += face_normals_[f];
      neighbour_sum[t[k]] += m.vertices[t[(k + 1) % 3]].cast<double>() + m.vertices[t[(k + 2) % 3]].cast<double>();
      neighbours[t[k]] += 2;
    }
  }
  std::vector<Vec3> all;
  for (size_t v = 0; v < m.vertices.size(); ++v) {
    if (!sharp[v] || neighbours[v] == 0) continue;
    const Vec3 p = m.vertices[v].cast<double>();
    if ((p - neighbour_sum[v] / neighbours[v]).dot(normal_sum[v]) > 0) all.push_back(p);
  }
  const size_t stride = (all.size() + kMaxSharp - 1) / kMaxSharp;
  for (size_t i = 0; i < all.size(); i += std::max<size_t>(stride, 1)) sharp_.push_back(all[i]);
  BuildClusters();
}

void GraspObject::BuildClusters() {
  // Recursive median splits along the longest axis down to kClusterSize vertices: tight balls for any shape.
  std::vector<uint32_t> order(sharp_.size());
  for (uint32_t i = 0; i < order.size(); ++i) order[i] = i;
  std::vector<std::pair<size_t, size_t>> stack = {{0, order.size()}};
  while (!stack.empty()) {
    const auto [begin, end] = stack.back();
    stack.pop_back();
    if (begin == end) continue;
    Vec3 lo = sharp_[order[begin]], hi = lo;
    for (size_t i = begin; i < end; ++i) lo = lo.cwiseMin(sharp_[order[i]]), hi = hi.cwiseMax(sharp_[order[i]]);
    if (end - begin > kClusterSize) {
      int axis;
      (hi - lo).maxCoeff(&axis);
      const size_t mid = (begin + end) / 2;
      std::nth_element(order.begin() + begin, order.begin() + mid, order.begin() + end,
                       [&](uint32_t x, uint32_t y) { return sharp_[x][axis] < sharp_[y][axis]; });
      stack.push_back({begin, mid});
      stack.push_back({mid, end});
      continue;
    }
    VertexCluster& cluster = clusters_.emplace_back();
    cluster.centre = 0.5 * (lo + hi);
    cluster.members.assign(order.begin() + begin, order.begin() + end);
    std::sort(cluster.members.begin(), cluster.members.end());
    for (uint32_t i : cluster.members) cluster.radius = std::max(cluster.radius, (sharp_[i] - cluster.centre).norm());
  }
}

bool BoxesOverlap(const LinkBox& a, const LinkBox& b, double margin) {
  const Vec3 d = b.centre - a.centre;
  auto separated = [&](const Vec3& axis) {
    const double length = axis.norm();
    if (length < 1e-12) return false;
    const Vec3 u = axis / length;
    const double ra = (a.axes.transpose() * u).cwiseAbs().dot(a.half);
    const double rb = (b.axes.transpose() * u).cwiseAbs().dot(b.half);
    return std::abs(d.dot(u)) > ra + rb + margin;
  };
  for (int i = 0; i < 3; ++i) {
    if (separated(a.axes.col(i)) || separated(b.axes.col(i))) return false;
  }
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) {
      if (separated(a.axes.col(i).cross(b.axes.col(j)))) return false;
    }
  }
  return true;
}

}  // namespace graspsim::grasp
