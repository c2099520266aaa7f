#include "perception/cloud_filters.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <string>

#include <Eigen/Eigenvalues>

#include "core/error.h"
#include "core/format.h"
#include "perception/neighbor_grid.h"

namespace graspsim {

namespace {

void CheckOutlierParams(int k, double std_ratio) {
  if (k < 1 || k > 100) ThrowInvalidArgument("outlier_k: " + std::to_string(k) + " is outside 1..100");
  if (!(std_ratio > 0) || !std::isfinite(std_ratio)) {
    ThrowInvalidArgument("outlier_std: " + FormatNumber(std_ratio) + " must be positive");
  }
}

}  // namespace

std::vector<uint32_t> StatisticalInliers(const std::vector<Vec3>& points, const CloudNeighbors& neighbors, int k,
                                         double std_ratio) {
  CheckOutlierParams(k, std_ratio);
  std::vector<uint32_t> kept;
  kept.reserve(points.size());
  if (points.size() <= size_t(k)) {
    for (size_t i = 0; i < points.size(); ++i) kept.push_back(uint32_t(i));
    return kept;
  }
  const std::vector<double> mean_distance = neighbors.MeanDistancesToNearest(points.size(), k);
  double sum = 0, sum_sq = 0;
  for (size_t i = 0; i < points.size(); ++i) {
    sum += mean_distance[i];
    sum_sq += mean_distance[i] * mean_distance[i];
  }
  const double n = double(points.size());
  const double mean = sum / n;
  const double sigma = std::sqrt(std::max(0.0, sum_sq / n - mean * mean));
  const double cut = mean + std_ratio * sigma;
  for (size_t i = 0; i < points.size(); ++i) {
    if (mean_distance[i] <= cut) kept.push_back(uint32_t(i));
  }
  return kept;
}

std::vector<Vec3> RemoveStatisticalOutliers(const std::vector<Vec3>& points, int k, double std_ratio) {
  CheckOutlierParams(k, std_ratio);
  if (points.size() <= size_t(k)) return points;
  const NeighborGrid grid(points, NeighborGrid::SuggestCellSize(points, k + 1));
  std::vector<Vec3> kept;
  kept.reserve(points.size());
  for (uint32_t i : StatisticalInliers(points, grid, k, std_ratio)) kept.push_back(points[i]);
  return kept;
}

namespace {

// floor(x) as an integer without the library call (std::floor is one where the build targets plain SSE2: three per
// point were most of the voxel pass). |x| < 2^52.
int64_t FloorToInt(double x) {
  const int64_t truncated = int64_t(x);
  return truncated - int64_t(x < double(truncated));
}

}  // namespace

size_t VoxelGroups(const std::vector<Vec3>& points, double voxel, const Vec3& origin, std::vector<uint32_t>* group) {
  if (!(voxel > 0) || !std::isfinite(voxel)) {
    ThrowInvalidArgument("voxel_size: " + FormatNumber(voxel) + " m must be positive");
  }
  // When the cubes over the points' bounding box are few (Poisson merging its samples per cell), a dense array of
  // them; else open addressing on the packed cube coordinates.
  group->resize(points.size());
  if (points.empty()) return 0;
  // By the inverse: three divisions a point were most of the pass (a point within rounding of a face may take the
  // cube beside it).
  const double inverse = 1 / voxel;
  Vec3 lo = points.front(), hi = points.front();
  for (const Vec3& p : points) lo = lo.cwiseMin(p), hi = hi.cwiseMax(p);
  // Cube coordinates within ±2^20 (the hash's 21 bits per axis; far below where a double stops counting whole
  // numbers): beyond, distinct cubes would share a key, and a voxel of 1e-30 m merged every point into one.
  const double farthest = std::max((lo - origin).cwiseAbs().maxCoeff(), (hi - origin).cwiseAbs().maxCoeff());
  if (!(farthest * inverse < double(1 << 20))) {
    ThrowInvalidArgument("voxel_size: " + FormatNumber(voxel) + " m is too small for points " +
                         FormatNumber(farthest) + " m from the grid's origin (at most 2^20 voxels along an axis)");
  }
  const auto cube_of = [&](const Vec3& p) {
    const Vec3 q = (p - origin) * inverse;
    return Eigen::Matrix<int64_t, 3, 1>(FloorToInt(q.x()), FloorToInt(q.y()), FloorToInt(q.z()));
  };
  const Eigen::Matrix<int64_t, 3, 1> first = cube_of(lo), extent = cube_of(hi) - first + decltype(first)::Ones();
  if (double(extent.x()) * double(extent.y()) * double(extent.z()) <= 4.0 * double(points.size()) + 64) {
    std::vector<int32_t> group_of_cube(size_t(extent.prod()), -1);
    uint32_t groups = 0;
    for (size_t i = 0; i < points.size(); ++i) {
      const Eigen::Matrix<int64_t, 3, 1> c = cube_of(points[i]) - first;
      const size_t cube = size_t((c.z() * extent.y() + c.y()) * extent.x() + c.x());
      if (group_of_cube[cube] < 0) group_of_cube[cube] = int32_t(groups++);
      (*group)[i] = uint32_t(group_of_cube[cube]);
    }
    return groups;
  }
  // Open addressing (a std::unordered_map was a third of the filter at 39k points): a power-of-two table at most
  // half full, linear probing; kEmpty is no packed key (those use 63 bits).
  constexpr uint64_t kEmpty = ~uint64_t(0);
  size_t slots = 16;
  while (slots < 2 * points.size()) slots *= 2;
  std::vector<uint64_t> keys(slots, kEmpty);
  std::vector<uint32_t> group_of_slot(slots);
  const int shift = 64 - __builtin_ctzll(slots);
  uint32_t groups = 0;
  for (size_t i = 0; i < points.size(); ++i) {
    // 21 bits per axis around the origin: ±2^20 cubes, far beyond any table-top object at mm voxels.
    const Eigen::Matrix<int64_t, 3, 1> c = cube_of(points[i]);
    const auto axis = [](int64_t x) { return uint64_t(x + (1 << 20)) & 0x1fffff; };
    const uint64_t key = axis(c.x()) | axis(c.y()) << 21 | axis(c.z()) << 42;
    size_t slot = size_t((key * 0x9E3779B97F4A7C15ull) >> shift);
    while (keys[slot] != kEmpty && keys[slot] != key) slot = (slot + 1) & (slots - 1);
    if (keys[slot] == kEmpty) {
      keys[slot] = key;
      group_of_slot[slot] = groups++;
    }
    (*group)[i] = group_of_slot[slot];
  }
  return groups;
}

std::vector<Vec3> VoxelDownsample(const std::vector<Vec3>& points, double voxel, std::vector<int64_t>* lone_source) {
  std::vector<uint32_t> group;
  const size_t groups = VoxelGroups(points, voxel, Vec3::Zero(), &group);
  std::vector<Vec3> sum(groups, Vec3::Zero());
  std::vector<int64_t> first(groups, -1);
  std::vector<int> count(groups, 0);
  for (size_t i = 0; i < points.size(); ++i) {
    sum[group[i]] += points[i];
    if (count[group[i]]++ == 0) first[group[i]] = int64_t(i);
  }
  for (size_t g = 0; g < groups; ++g) sum[g] /= count[g];
  if (lone_source) {
    lone_source->resize(groups);
    for (size_t g = 0; g < groups; ++g) (*lone_source)[g] = count[g] == 1 ? first[g] : -1;
  }
  return sum;
}

Vec3 SpreadEigenvalues(const std::vector<Vec3>& points) {
  // One pass over sums relative to the first point (a cloud's extent, not its distance from the origin, sets the
  // digits lost), the six distinct entries by hand: Eigen's 3 × 3 outer product per point was a twentieth of a
  // 94k-point surface.
  const Vec3 origin = points.front();
  double x = 0, y = 0, z = 0, xx = 0, xy = 0, xz = 0, yy = 0, yz = 0, zz = 0;
  for (const Vec3& p : points) {
    const double dx = p.x() - origin.x(), dy = p.y() - origin.y(), dz = p.z() - origin.z();
    x += dx, y += dy, z += dz;
    xx += dx * dx, xy += dx * dy, xz += dx * dz, yy += dy * dy, yz += dy * dz, zz += dz * dz;
  }
  const double n = double(points.size());
  Mat3 covariance;
  covariance << xx - x * x / n, xy - x * y / n, xz - x * z / n,  //
      xy - x * y / n, yy - y * y / n, yz - y * z / n,            //
      xz - x * z / n, yz - y * z / n, zz - z * z / n;
  return Eigen::SelfAdjointEigenSolver<Mat3>(covariance, Eigen::EigenvaluesOnly).eigenvalues();
}

}  // namespace graspsim
