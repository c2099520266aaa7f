#include "perception/neighbor_grid.h"

#include <algorithm>
#include <cmath>
#include <utility>

namespace graspsim {

double CloudNeighbors::MeanDistanceToNearest(uint32_t i, int k) const {
  std::vector<uint32_t> nearest;  // not thread_local: the perception library is position-independent code, and
                                  // its TLS would make every binary link the dynamic loader (test_deploy_files.py)
  NearestTo(i, k + 1, &nearest);  // the point itself comes first
  double sum = 0;
  for (size_t j = 1; j < nearest.size(); ++j) sum += (Point(nearest[j]) - Point(i)).norm();
  return nearest.size() > 1 ? sum / double(nearest.size() - 1) : 0;
}

std::vector<double> CloudNeighbors::MeanDistancesToNearest(size_t count, int k) const {
  std::vector<double> distances(count);
  for (size_t i = 0; i < count; ++i) distances[i] = MeanDistanceToNearest(uint32_t(i), k);
  return distances;
}

NeighborGrid::NeighborGrid(const std::vector<Vec3>& points, double cell_size) : points_(points), cell_size_(cell_size) {
  Vec3 lo = points.front(), hi = points.front();
  for (const Vec3& p : points) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  origin_ = lo;
  // Dense buckets: keep their count near the point count (a degenerate or sparse cloud gets bigger cells).
  const double max_cells = 4.0 * double(points.size()) + 64.0;
  for (;;) {
    const Vec3 extent = (hi - lo) / cell_size_;
    dims_ = Eigen::Vector3i(int(extent.x()) + 1, int(extent.y()) + 1, int(extent.z()) + 1);
    if (double(dims_[0]) * dims_[1] * dims_[2] <= max_cells) break;
    cell_size_ *= 1.5;
  }
  const int64_t cells = int64_t(dims_[0]) * dims_[1] * dims_[2];
  cell_start_.assign(cells + 1, 0);
  std::vector<int64_t> cell_of(points.size());
  for (size_t i = 0; i < points.size(); ++i) {
    const Eigen::Vector3i c = CellOf(points[i]);
    cell_of[i] = CellIndex(c.x(), c.y(), c.z());
    ++cell_start_[cell_of[i] + 1];
  }
  for (int64_t c = 0; c < cells; ++c) cell_start_[c + 1] += cell_start_[c];
  order_.resize(points.size());
  std::vector<uint32_t> fill(cell_start_.begin(), cell_start_.end() - 1);
  for (size_t i = 0; i < points.size(); ++i) order_[fill[cell_of[i]]++] = uint32_t(i);  // ascending within a cell
}

Eigen::Vector3i NeighborGrid::CellOf(const Vec3& p) const {
  Eigen::Vector3i c;
  for (int a = 0; a < 3; ++a) c[a] = std::clamp(int(std::floor((p[a] - origin_[a]) / cell_size_)), 0, dims_[a] - 1);
  return c;
}

void NeighborGrid::Nearest(const Vec3& query, int k, std::vector<uint32_t>* out) const {
  out->clear();
  if (k <= 0) return;
  KNearest best(k);
  const Eigen::Vector3i center = CellOf(query);
  const int max_ring = dims_.maxCoeff();
  for (int ring = 0; ring <= max_ring; ++ring) {
    const Eigen::Vector3i lo = (center.array() - ring).max(0), hi = (center.array() + ring).min(dims_.array() - 1);
    for (int z = lo.z(); z <= hi.z(); ++z) {
      for (int y = lo.y(); y <= hi.y(); ++y) {
        const bool inner_zy = std::abs(z - center.z()) < ring && std::abs(y - center.y()) < ring;
        for (int x = lo.x(); x <= hi.x(); ++x) {
          // Only the shell of this ring: the inside was visited by the smaller rings.
          if (inner_zy && std::abs(x - center.x()) < ring) {
            x = center.x() + ring - 1;
            continue;
          }
          const int64_t c = CellIndex(x, y, z);
          if (cell_start_[c] == cell_start_[c + 1]) continue;
          if (best.Full()) {  // skip a cell that lies wholly beyond the k-th nearest so far
            const Vec3 lo = origin_ + cell_size_ * Vec3(x, y, z);
            const Vec3 gap = (lo - query).cwiseMax(query - lo - Vec3::Constant(cell_size_)).cwiseMax(0.0);
            if (gap.squaredNorm() > best.Worst()) continue;
          }
          for (uint32_t j = cell_start_[c]; j < cell_start_[c + 1]; ++j) {
            best.Offer((points_[order_[j]] - query).squaredNorm(), order_[j]);
          }
        }
      }
    }
    // Every cell of ring r + 1 lies at least r cell sizes from the query (it sits inside the centre cell).
    const double reach = ring * cell_size_;
    if (best.Full() && best.Worst() <= reach * reach) break;
  }
  best.Write(out);
}

double NeighborGrid::SuggestCellSize(const std::vector<Vec3>& points, int k) {
  Vec3 lo = points.front(), hi = points.front();
  for (const Vec3& p : points) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  const double diagonal = (hi - lo).norm();
  const double spacing = diagonal / std::sqrt(double(points.size()));
  return std::max(spacing * std::sqrt(double(std::max(k, 1))) * 0.5, 1e-9);
}

double NeighborGrid::MedianSpacing(const std::vector<Vec3>& points) {
  if (points.size() < 2) return 1e-3;
  const NeighborGrid grid(points, NeighborGrid::SuggestCellSize(points, 2));
  const size_t stride = std::max<size_t>(1, points.size() / 256);
  std::vector<double> gaps;
  std::vector<uint32_t> nearest;
  for (size_t i = 0; i < points.size(); i += stride) {
    grid.Nearest(points[i], 2, &nearest);
    gaps.push_back((points[nearest.back()] - points[i]).norm());
  }
  std::nth_element(gaps.begin(), gaps.begin() + gaps.size() / 2, gaps.end());
  return gaps[gaps.size() / 2] > 0 ? gaps[gaps.size() / 2] : 1e-3;
}

}  // namespace graspsim
