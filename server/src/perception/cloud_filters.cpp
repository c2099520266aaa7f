#include "perception/cloud_filters.h"

#include <cmath>
#include <cstdint>
#include <string>
#include <unordered_map>

#include "core/error.h"
#include "core/format.h"
#include "perception/neighbor_grid.h"

namespace graspsim {

std::vector<Vec3> RemoveStatisticalOutliers(const std::vector<Vec3>& points, int k, double std_ratio) {
  if (k < 1 || k > 100) ThrowInvalidArgument("outlier_k: " + std::to_string(k) + " is outside 1..100");
  if (!(std_ratio > 0) || !std::isfinite(std_ratio)) {
    ThrowInvalidArgument("outlier_std: " + FormatNumber(std_ratio) + " must be positive");
  }
  if (points.size() <= size_t(k)) return points;
  const NeighborGrid grid(points, NeighborGrid::SuggestCellSize(points, k + 1));
  std::vector<double> mean_distance(points.size());
  std::vector<uint32_t> nearest;
  double sum = 0, sum_sq = 0;
  for (size_t i = 0; i < points.size(); ++i) {
    grid.Nearest(points[i], k + 1, &nearest);  // the point itself comes first
    double d = 0;
    for (size_t j = 1; j < nearest.size(); ++j) d += (points[nearest[j]] - points[i]).norm();
    mean_distance[i] = d / double(nearest.size() - 1);
    sum += mean_distance[i];
    sum_sq += mean_distance[i] * mean_distance[i];
  }
  const double n = double(points.size());
  const double mean = sum / n;
  const double sigma = std::sqrt(std::max(0.0, sum_sq / n - mean * mean));
  const double cut = mean + std_ratio * sigma;
  std::vector<Vec3> kept;
  kept.reserve(points.size());
  for (size_t i = 0; i < points.size(); ++i) {
    if (mean_distance[i] <= cut) kept.push_back(points[i]);
  }
  return kept;
}

std::vector<Vec3> VoxelDownsample(const std::vector<Vec3>& points, double voxel) {
  if (!(voxel > 0) || !std::isfinite(voxel)) {
    ThrowInvalidArgument("voxel_size: " + FormatNumber(voxel) + " m must be positive");
  }
  struct Cell {
    Vec3 sum = Vec3::Zero();
    int count = 0;
  };
  std::unordered_map<uint64_t, uint32_t> index;  // packed cell coordinates → slot in cells
  std::vector<Cell> cells;
  index.reserve(points.size());
  for (const Vec3& p : points) {
    // 21 bits per axis around the origin: ±2^20 voxels, far beyond any table-top object at mm voxels.
    const auto axis = [voxel](double x) { return uint64_t(int64_t(std::floor(x / voxel)) + (1 << 20)) & 0x1fffff; };
    const uint64_t key = axis(p.x()) | axis(p.y()) << 21 | axis(p.z()) << 42;
    auto [it, added] = index.try_emplace(key, uint32_t(cells.size()));
    if (added) cells.emplace_back();
    cells[it->second].sum += p;
    ++cells[it->second].count;
  }
  std::vector<Vec3> out;
  out.reserve(cells.size());
  for (const Cell& c : cells) out.push_back(c.sum / c.count);
  return out;
}

}  // namespace graspsim
