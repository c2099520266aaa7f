#include "perception/image_neighbors.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <utility>

#include "core/error.h"

namespace graspsim {

PixelIndex::PixelIndex(int image_width, const std::vector<uint32_t>& pixels) {
  int u_lo = std::numeric_limits<int>::max(), u_hi = -1, v_lo = std::numeric_limits<int>::max(), v_hi = -1;
  for (uint32_t p : pixels) {
    const int u = int(p % uint32_t(image_width)), v = int(p / uint32_t(image_width));
    u_lo = std::min(u_lo, u), u_hi = std::max(u_hi, u), v_lo = std::min(v_lo, v), v_hi = std::max(v_hi, v);
  }
  if (pixels.empty()) return;
  u0 = u_lo, v0 = v_lo;
  width = u_hi - u_lo + 1, height = v_hi - v_lo + 1;
  point_at.assign(size_t(width) * size_t(height), -1);
  local.resize(pixels.size());
  for (size_t i = 0; i < pixels.size(); ++i) {
    const int u = int(pixels[i] % uint32_t(image_width)) - u0, v = int(pixels[i] / uint32_t(image_width)) - v0;
    local[i] = {u, v};
    point_at[size_t(v) * size_t(width) + size_t(u)] = int32_t(i);
  }
}

ImageNeighbors::ImageNeighbors(const CameraIntrinsics& intrinsics, const std::vector<Vec3>& points,
                               const std::vector<uint32_t>& pixels, int radius_px)
    : radius_(radius_px), points_(points), index_(intrinsics.width, pixels) {
  if (pixels.size() != points.size()) {
    throw Error(ErrorCode::kInternal, "ImageNeighbors: " + std::to_string(pixels.size()) + " pixels for " +
                                          std::to_string(points.size()) + " points");
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
  index_.ForEachInWindow(i, radius_, [&](uint32_t j) {
    if (j != i) distances[found++] = (points_[j] - query).squaredNorm();
  });
  const size_t count = std::min(found, size_t(std::max(k, 0)));
  if (count < found) std::nth_element(distances, distances + count, distances + found);
  double sum = 0;
  for (size_t j = 0; j < count; ++j) sum += std::sqrt(distances[j]);
  return count ? sum / double(count) : 0;
}

std::vector<double> ImageNeighbors::MeanDistancesToNearest(size_t count, int k) const {
  if (radius_ != 1 || k < 8 || count != points_.size()) return CloudNeighbors::MeanDistancesToNearest(count, k);
  std::vector<double> sums(count, 0.0);
  std::vector<uint8_t> found(count, 0);
  const int w = index_.width, h = index_.height;
  // Each point with its neighbours right, below left, below and below right: every pair of the 3 × 3 once.
  for (int v = 0; v < h; ++v) {
    const int32_t* row = index_.point_at.data() + size_t(v) * size_t(w);
    const int32_t* below = v + 1 < h ? row + w : nullptr;
    for (int u = 0; u < w; ++u) {
      const int32_t i = row[u];
      if (i < 0) continue;
      const auto pair = [&](int32_t j) {
        if (j < 0) return;
        const double d = (points_[size_t(j)] - points_[size_t(i)]).norm();
        sums[size_t(i)] += d, sums[size_t(j)] += d;
        ++found[size_t(i)], ++found[size_t(j)];
      };
      if (u + 1 < w) pair(row[u + 1]);
      if (below) {
        if (u > 0) pair(below[u - 1]);
        pair(below[u]);
        if (u + 1 < w) pair(below[u + 1]);
      }
    }
  }
  for (size_t i = 0; i < count; ++i) sums[i] = found[i] ? sums[i] / found[i] : 0;
  return sums;
}

void ImageNeighbors::NearestTo(uint32_t i, int k, std::vector<uint32_t>* out) const {
  KNearest best(k);  // NeighborGrid's order
  index_.ForEachInWindow(i, radius_, [&](uint32_t j) { best.Offer((points_[j] - points_[i]).squaredNorm(), j); });
  best.Write(out);
}

}  // namespace graspsim
