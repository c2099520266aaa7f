// What a camera saw of one object (PAPERS.md part C, "Score"): the object's points in the world and the picture
// they came from — a depth image and a segmentation mask seen through a pinhole camera — which the symmetry
// search needs to tell a plausible mirrored point (hidden from the camera) from an implausible one (where the
// camera looked and saw nothing, or saw something farther away).
//
// Camera frame: z forward (the optical axis), x right, y down; pixel (u, v) = (column, row) with
// u = fx x / z + cx, v = fy y / z + cy, pixel centres at integer (u, v). Depth = z in m.
#pragma once

#include <cstdint>
#include <optional>
#include <vector>

#include "core/math.h"

namespace graspsim {

struct CameraIntrinsics {
  int width = 0, height = 0;  // pixels
  double fx = 0, fy = 0;      // pixels
  double cx = 0, cy = 0;      // pixels
};

struct DepthImage {
  CameraIntrinsics intrinsics;
  std::vector<float> depth;   // width × height, row-major, m along the optical axis; 0 or NaN = no return
  std::vector<uint8_t> mask;  // width × height, nonzero = object pixel; empty = every pixel with a depth
};

// A box of pixels, inclusive; u_hi < 0 when empty.
struct PixelBox {
  int u_lo = 0, v_lo = 0, u_hi = -1, v_hi = -1;
};

// The input of shape completion: an organized depth image, or unorganized points, with the camera pose.
struct PartialView {
  std::optional<DepthImage> image;  // organized input; when absent, `points`
  std::vector<Vec3> points;         // unorganized input: the object's points, m, world frame
  Pose camera_pose;                 // the camera frame in the world
};

// The object as the score sees it. For organized input the camera is the real one; for unorganized points a
// virtual camera at the same pose is derived (`derived_camera`): its focal length makes one pixel ≈ 1.5 × the
// points' spacing at their median depth, the image just covers their projection (plus a margin), the depth is
// the nearest point per pixel and the mask the pixels hit, closed by a 3 × 3 morphological closing.
struct Observation {
  std::vector<Vec3> points;      // the object's points, world frame, m
  std::vector<uint32_t> pixels;  // organized input: the pixel each point was seen at (empty for a derived camera)
  Pose camera_pose;              // camera in world
  CameraIntrinsics intrinsics;
  std::vector<float> depth;      // observed depth per pixel, m; +inf where there was no return
  std::vector<uint8_t> mask;     // 1 = object pixel
  PixelBox mask_box;             // the mask's bounding box (the symmetry score's and the free space's windows)
  bool derived_camera = false;

  Vec3 CameraCentre() const { return camera_pose.position; }
};

// True when any two of a depth image's points (one per pixel) lie farther apart than `distance` (m): a point within
// r of p projects within f r √(1 + t²) / (z − r) pixels of p's pixel (t = the ray's slope), and that is below one
// pixel for r = distance at every point's depth and slope. A voxel filter whose cubes' diagonal is that distance
// then keeps every point as it is. Always false for unorganized input.
bool PointsFartherApartThan(const Observation& observation, double distance);

// The median of the observed depths at `pixels` (non-empty), m.
double MedianDepth(const Observation& observation, const std::vector<uint32_t>& pixels);

// Validates and converts the input. Errors name the request's fields: kInvalidArgument for an empty cloud, a
// non-finite point, a point behind the camera, bad intrinsics, a depth or mask of the wrong size, an image with
// no finite depth in the mask; kResourceExhausted for more than `max_points` points (or pixels).
Observation Observe(const PartialView& view, size_t max_points);

}  // namespace graspsim
