// Space the camera saw to be empty (PAPERS.md part C's visibility score, turned on the completed surface): the
// object lies along no ray outside its mask (the silhouette), and not in front of the depth observed inside it.
// Shape completion clears such space from the indicator before extracting the mesh, so the surface cannot grow
// where the camera looked and saw nothing (issue 22: a closed-up mug rising 40 mm over its rim, a can 27 mm taller
// than it is, both in plain view of the camera).
#pragma once

#include <cstdint>
#include <vector>

#include "core/math.h"
#include "perception/observation.h"

namespace graspsim {

class SeenFreeSpace {
 public:
  // Points projecting outside the mask by more than margin_px pixels are empty space. Within the margin (the mask's
  // edge is quantised to pixels) and on the mask they are when they lie before the least depth the mask shows
  // around their pixel by more than depth_margin (m; the depth is noisy, and changes fast across a grazing face).
  // Points behind the camera, outside its image, or where no depth was seen are unknown.
  SeenFreeSpace(const Observation& observation, double margin_px, double depth_margin);

  // True when the camera saw `world_point` (m, world frame) empty.
  bool Contains(const Vec3& world_point) const;

 private:
  CameraIntrinsics intrinsics_;
  Pose world_to_camera_;
  double depth_margin_;
  struct Window {
    int x = 0, y = 0, width = 0, height = 0;
  } window_;                            // the mask's bounding box grown by the margin, clipped to the image
  static constexpr float kBeyond = -1;  // outside the mask by more than the margin
  std::vector<float> near_depth_;        // per pixel of the window: kBeyond, or the depth to test (free_space.cpp)
};

}  // namespace graspsim
