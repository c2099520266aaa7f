// Neighbours of the points of a depth image found through the image: the k nearest in space among the points
// seen within a small square window of pixels around each point, instead of among the whole cloud.
//
// On a depth camera's cloud the noise along the rays (~1 mm) exceeds the pixel spacing (~0.3–0.5 mm at table-top
// range), so a point's k nearest in the whole cloud lie several pixels away in any direction (the exact search
// has to read ~200 pixels or walk a grid: 1 µs a point), while the window holds the ones on the same patch of
// surface: a filter that asks "is this point far from its neighbours?" (statistical outlier removal) gets the same
// verdict for a fraction of the cost. Not the exact k nearest: use NeighborGrid where that matters.
#pragma once

#include <algorithm>
#include <cstdint>
#include <utility>
#include <vector>

#include "core/math.h"
#include "perception/neighbor_grid.h"
#include "perception/observation.h"

namespace graspsim {

// The points of a depth image by pixel, over their pixels' bounding box only (a table-top object fills a small
// part of the view): the point seen at each pixel, −1 for none. pixels[i] is point i's pixel in an image
// `image_width` wide; at most one point per pixel.
struct PixelIndex {
  PixelIndex(int image_width, const std::vector<uint32_t>& pixels);

  // Calls f(j) for each point j seen within `radius` pixels of point i in both directions (i itself included),
  // row by row.
  template <typename F>
  void ForEachInWindow(uint32_t i, int radius, F&& f) const {
    const auto [at_u, at_v] = local[i];
    const int u_lo = std::max(0, at_u - radius), u_hi = std::min(width - 1, at_u + radius);
    for (int v = std::max(0, at_v - radius); v <= std::min(height - 1, at_v + radius); ++v) {
      const int32_t* row = point_at.data() + size_t(v) * size_t(width);
      for (int u = u_lo; u <= u_hi; ++u) {
        if (row[u] >= 0) f(uint32_t(row[u]));
      }
    }
  }

  int u0 = 0, v0 = 0, width = 0, height = 0;  // the box, in the image's pixels
  std::vector<int32_t> point_at;              // per pixel of the box, row-major
  std::vector<std::pair<int, int>> local;     // per point: its pixel (u, v) in the box
};

class ImageNeighbors : public CloudNeighbors {
 public:
  // points[i] (world frame) was seen at pixel pixels[i] of the observation's image; at most one point per pixel.
  // The window is (2 radius_px + 1)² pixels. `points` must outlive this.
  ImageNeighbors(const CameraIntrinsics& intrinsics, const std::vector<Vec3>& points,
                 const std::vector<uint32_t>& pixels, int radius_px);

  // The k nearest to point i (itself first) among the points of its window, nearest first, ties to the lower
  // index; fewer than k when the window holds fewer.
  void NearestTo(uint32_t i, int k, std::vector<uint32_t>* out) const override;
  // Without sorting when the window holds at most k others (the 3 × 3 window of the outlier test's k = 8).
  double MeanDistanceToNearest(uint32_t i, int k) const override;
  // In a 3 × 3 window with k ≥ 8 (every other point of the window counts), each pair's distance once for both.
  std::vector<double> MeanDistancesToNearest(size_t count, int k) const override;
  const Vec3& Point(uint32_t i) const override { return points_[i]; }

  // The smallest radius whose window holds k pixels (k = 9, the outlier test's 8 and the point: 3 × 3).
  static int RadiusFor(int k);

 private:
  int radius_;
  const std::vector<Vec3>& points_;
  PixelIndex index_;
};

}  // namespace graspsim
