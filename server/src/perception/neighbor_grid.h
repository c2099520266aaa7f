// k-nearest-neighbour queries on an unorganized point cloud through a uniform grid of buckets (the points of a
// depth camera are spread evenly over surfaces, so a grid sized to the sample spacing answers a query from a few
// cells; no tree to build). Results are exact and deterministic: ties in distance go to the lower index.
#pragma once

#include <algorithm>
#include <cstdint>
#include <vector>

#include "core/math.h"

namespace graspsim {

// The k nearest neighbours of a cloud's own points: through a grid (any cloud, below) or through the image the
// points were seen in (image_neighbors.h). Both give the same exact answer.
class CloudNeighbors {
 public:
  virtual ~CloudNeighbors() = default;
  // The indices of the k points nearest to point i (itself included), nearest first, ties to the lower index.
  virtual void NearestTo(uint32_t i, int k, std::vector<uint32_t>* out) const = 0;
  // The mean distance from point i to its k nearest others (the outlier test's figure; 0 when it has none).
  virtual double MeanDistanceToNearest(uint32_t i, int k) const;
  // The same for every point, i = 0 .. count − 1.
  virtual std::vector<double> MeanDistancesToNearest(size_t count, int k) const;
  virtual const Vec3& Point(uint32_t i) const = 0;
};

// The best k candidates offered so far, ascending by (squared distance, index): ties go to the lower index.
// Insertion into a short sorted array beats a heap for the k of normals and outlier tests (≈ 10) and allocates
// nothing for k ≤ 32.
class KNearest {
 public:
  explicit KNearest(int k) : k_(std::max(k, 0)) {
    if (k_ > kLocal) spill_.resize(size_t(k_));
  }
  bool Full() const { return count_ == k_; }
  double Worst() const { return best()[k_ - 1].d; }  // the k-th squared distance; only when Full()
  void Offer(double squared_distance, uint32_t index) {
    const Item item{squared_distance, index};
    Item* best = this->best();
    if (k_ == 0 || (count_ == k_ && !(item < best[k_ - 1]))) return;
    int at = count_ < k_ ? count_++ : k_ - 1;
    for (; at > 0 && item < best[at - 1]; --at) best[at] = best[at - 1];
    best[at] = item;
  }
  // The indices, nearest first.
  void Write(std::vector<uint32_t>* out) const {
    out->resize(size_t(count_));
    for (int j = 0; j < count_; ++j) (*out)[j] = best()[j].i;
  }

 private:
  struct Item {
    double d;
    uint32_t i;
    bool operator<(const Item& o) const { return d < o.d || (d == o.d && i < o.i); }
  };
  static constexpr int kLocal = 32;
  Item* best() { return k_ > kLocal ? spill_.data() : local_; }
  const Item* best() const { return k_ > kLocal ? spill_.data() : local_; }
  int k_, count_ = 0;
  Item local_[kLocal];
  std::vector<Item> spill_;
};

class NeighborGrid : public CloudNeighbors {
 public:
  // `points` must outlive the grid and be non-empty. `cell_size` (m) > 0 only sets the speed, never the answer.
  NeighborGrid(const std::vector<Vec3>& points, double cell_size);

  // The indices of the k points nearest to `query` (itself included when it is one of the points), nearest first.
  // Fewer than k only when the cloud has fewer points.
  void Nearest(const Vec3& query, int k, std::vector<uint32_t>* out) const;
  void NearestTo(uint32_t i, int k, std::vector<uint32_t>* out) const override { Nearest(points_[i], k, out); }
  const Vec3& Point(uint32_t i) const override { return points_[i]; }

  // A cell size for ~k neighbours within a ring or two of cells when the points sample a surface: the mean
  // sample spacing estimated from the bounding box (the area of a surface in a box grows like its diagonal²).
  static double SuggestCellSize(const std::vector<Vec3>& points, int k);

  // The median distance from a point to its nearest other point, over up to 256 points spread through the cloud
  // (1 mm for fewer than 2 points or all coincident).
  static double MedianSpacing(const std::vector<Vec3>& points);

 private:
  int64_t CellIndex(int x, int y, int z) const { return (int64_t(z) * dims_[1] + y) * dims_[0] + x; }
  Eigen::Vector3i CellOf(const Vec3& p) const;

  const std::vector<Vec3>& points_;
  double cell_size_;
  Vec3 origin_;
  Eigen::Vector3i dims_;
  std::vector<uint32_t> cell_start_;  // CSR: the points of cell c are order_[cell_start_[c] .. cell_start_[c + 1])
  std::vector<uint32_t> order_;
};

}  // namespace graspsim
