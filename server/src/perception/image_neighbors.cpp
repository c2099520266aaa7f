#include "perception/image_neighbors.h"

#include <algorithm>
#include <cmath>
#include <string>
#include <utility>

#include "core/error.h"

namespace graspsim {

ImageNeighbors::ImageNeighbors(const CameraIntrinsics& intrinsics, const std::vector<Vec3>& points,
                               const std::vector<uint32_t>& pixels, int radius_px)
    : image_width_(intrinsics.width), radius_(radius_px), points_(points) {
  if (pixels.size() != points.size()) {
    throw Error(ErrorCode::kInternal, "ImageNeighbors: " + std::to_string(pixels.size()) + " pixels for " +
                                          std::to_string(points.size()) + " points");
  }
  // The index image covers the pixels' bounding box only (a table-top object fills a small part of the view).
  int u_lo = intrinsics.width, u_hi = -1, v_lo = intrinsics.height, v_hi = -1;
  for (uint32_t p : pixels) {
    const int u = int(p % uint32_t(image_width_)), v = int(p / uint32_t(image_width_));
    u_lo = std::min(u_lo, u), u_hi = std::max(u_hi, u), v_lo = std::min(v_lo, v), v_hi = std::max(v_hi, v);
  }
  u0_ = u_lo, v0_ = v_lo;
  width_ = std::max(0, u_hi - u_lo + 1), height_ = std::max(0, v_hi - v_lo + 1);
  point_at_.assign(size_t(width_) * size_t(height_), -1);
  local_.resize(pixels.size());
  for (size_t i = 0; i < pixels.size(); ++i) {
    const int u = int(pixels[i] % uint32_t(image_width_)) - u0_, v = int(pixels[i] / uint32_t(image_width_)) - v0_;
    local_[i] = {u, v};
    point_at_[size_t(v) * width_ + u] = int32_t(i);
  }
}

int ImageNeighbors::RadiusFor(int k) {
  return std::max(1, int(std::ceil((std::sqrt(double(std::max(k, 1))) - 1) / 2)));
}

double ImageNeighbors::MeanDistanceToNearest(uint32_t i, int k) const {
  // The window's squared distances: on the stack for the outlier test's 3 × 3 (up to 15 × 15), else on the heap.
  const size_t window = size_t(2 * radius_ + 1) * size_t(2 * radius_ + 1);
  double local[225];
  std::vector<double> heap;
  if (window > 225) heap.resize(window);
  double* distances = window > 225 ? heap.data() : local;
  size_t found = 0;
  const Vec3& query = points_[i];
  const int u0 = local_[i].first, v0 = local_[i].second;
  const int u_lo = std::max(0, u0 - radius_), u_hi = std::min(width_ - 1, u0 + radius_);
  for (int v = std::max(0, v0 - radius_); v <= std::min(height_ - 1, v0 + radius_); ++v) {
    const int32_t* row = point_at_.data() + size_t(v) * width_;
    for (int u = u_lo; u <= u_hi; ++u) {
      if (row[u] >= 0 && uint32_t(row[u]) != i) distances[found++] = (points_[row[u]] - query).squaredNorm();
    }
  }
  const size_t count = std::min(found, size_t(std::max(k, 0)));
  if (count < found) std::nth_element(distances, distances + count, distances + found);
  double sum = 0;
  for (size_t j = 0; j < count; ++j) sum += std::sqrt(distances[j]);
  return count ? sum / double(count) : 0;
}

void ImageNeighbors::NearestTo(uint32_t i, int k, std::vector<uint32_t>* out) const {
  // The best k so far, ascending by (squared distance, index): NeighborGrid's order. Insertion into a short
  // sorted array, as the grid does: the window holds a few dozen points.
  struct Item {
    double d;
    uint32_t i;
    bool operator<(const Item& o) const { return d < o.d || (d == o.d && i < o.i); }
  };
  Item local[32];
  std::vector<Item> spill;
  Item* best = local;
  if (k > 32) {
    spill.resize(size_t(k));
    best = spill.data();
  }
  int count = 0;
  const Vec3& query = points_[i];
  const int u0 = local_[i].first, v0 = local_[i].second;
  const int u_lo = std::max(0, u0 - radius_), u_hi = std::min(width_ - 1, u0 + radius_);
  for (int v = std::max(0, v0 - radius_); v <= std::min(height_ - 1, v0 + radius_); ++v) {
    const int32_t* row = point_at_.data() + size_t(v) * width_;
    for (int u = u_lo; u <= u_hi; ++u) {
      if (row[u] < 0) continue;
      const Item item{(points_[row[u]] - query).squaredNorm(), uint32_t(row[u])};
      if (count == k && !(item < best[k - 1])) continue;
      int at = count < k ? count++ : k - 1;
      for (; at > 0 && item < best[at - 1]; --at) best[at] = best[at - 1];
      best[at] = item;
    }
  }
  out->resize(size_t(count));
  for (int j = 0; j < count; ++j) (*out)[j] = best[j].i;
}

}  // namespace graspsim
