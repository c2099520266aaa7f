// Neighbours of the points of a depth image found through the image: the k nearest in space among the points
// seen within a small square window of pixels around each point, instead of among the whole cloud.
//
// On a depth camera's cloud the noise along the rays (~1 mm) exceeds the pixel spacing (~0.3–0.5 mm at table-top
// range), so a point's k nearest in the whole cloud lie several pixels away in any direction (the exact search
// has to read ~200 pixels or walk a grid: 1 µs a point), while the window holds the ones on the same patch of
// surface: a filter that asks "is this point far from its neighbours?" (statistical outlier removal) gets the same
// verdict for a fraction of the cost. Not the exact k nearest: use NeighborGrid where that matters.
#pragma once

#include <cstdint>
#include <utility>
#include <vector>

#include "core/math.h"
#include "perception/neighbor_grid.h"
#include "perception/observation.h"

namespace graspsim {

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
  const Vec3& Point(uint32_t i) const override { return points_[i]; }

  // The smallest radius whose window holds k pixels (k = 9, the outlier test's 8 and the point: 3 × 3).
  static int RadiusFor(int k);

 private:
  int image_width_, radius_;
  const std::vector<Vec3>& points_;
  int u0_ = 0, v0_ = 0, width_ = 0, height_ = 0;  // the pixels' bounding box
  std::vector<int32_t> point_at_;                // per pixel of the box: the point seen there, −1 for none
  std::vector<std::pair<int, int>> local_;       // per point: its pixel in the box
};

}  // namespace graspsim
