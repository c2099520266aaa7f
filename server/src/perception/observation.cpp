#include "perception/observation.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include <opencv2/imgproc.hpp>

#include "core/error.h"
#include "core/format.h"
#include "core/validate.h"
#include "perception/neighbor_grid.h"

namespace graspsim {
namespace {

constexpr float kNoReturn = std::numeric_limits<float>::infinity();
// Derived camera (unorganized input): a pixel covers this many sample spacings, so neighbouring points fall into
// neighbouring pixels and a 3 × 3 closing fills what falls between.
constexpr double kPixelsPerSpacing = 1.0 / 1.5;
constexpr int kDerivedMargin = 8;  // pixels around the projection
constexpr int kMaxDerivedSide = 2048;

std::string Count(size_t n) { return std::to_string(n); }


void CheckLimit(const std::string& field, size_t count, const char* what, size_t max_points) {
  if (count > max_points) {
    ThrowResourceExhausted(field + ": " + Count(count) + " " + what + " exceed the limit of " + Count(max_points) +
                           " (--max-cloud-points)");
  }
}

void CheckIntrinsics(const CameraIntrinsics& k) {
  const std::string f = "depth_image.intrinsics.";
  if (k.width <= 0 || k.height <= 0) {
    ThrowInvalidArgument(f + "width/height: " + std::to_string(k.width) + " x " + std::to_string(k.height) +
                         " pixels; both must be positive");
  }
  for (auto [name, value] : {std::pair{"fx", k.fx}, {"fy", k.fy}}) {
    CheckFinite(f + name, value);
    if (value <= 0) ThrowInvalidArgument(f + name + ": " + FormatNumber(value) + " pixels; must be positive");
  }
  CheckFinite(f + "cx", k.cx);
  CheckFinite(f + "cy", k.cy);
}

Observation FromImage(const DepthImage& image, const Pose& camera_pose, size_t max_points) {
  const CameraIntrinsics& k = image.intrinsics;
  CheckIntrinsics(k);
  const size_t pixels = size_t(k.width) * size_t(k.height);
  CheckLimit("depth_image", pixels, "pixels", max_points);
  const std::string size = " for a " + std::to_string(k.width) + " x " + std::to_string(k.height) + " image (" +
                           Count(pixels) + " expected)";
  if (image.depth.size() != pixels) {
    ThrowInvalidArgument("depth_image.depth: " + Count(image.depth.size()) + " values" + size);
  }
  if (!image.mask.empty() && image.mask.size() != pixels) {
    ThrowInvalidArgument("depth_image.mask: " + Count(image.mask.size()) + " bytes" + size);
  }
  Observation obs;
  obs.camera_pose = camera_pose;
  obs.intrinsics = k;
  obs.depth.resize(pixels);
  obs.mask.assign(pixels, 0);
  // Row by row, with the rotation as a matrix and the rays' slopes per column and row (a quaternion product and
  // two divisions per pixel were a twentieth of a 39k-point completion).
  const Mat3 rotation = camera_pose.orientation.toRotationMatrix();
  std::vector<double> slope_u(size_t(k.width));
  for (int u = 0; u < k.width; ++u) slope_u[size_t(u)] = (u - k.cx) / k.fx;
  for (int v = 0; v < k.height; ++v) {
    const double slope_v = (v - k.cy) / k.fy;
    const size_t row = size_t(v) * size_t(k.width);
    for (int u = 0; u < k.width; ++u) {
      const size_t i = row + size_t(u);
      const float z = image.depth[i];
      const bool valid = std::isfinite(z) && z > 0;
      obs.depth[i] = valid ? z : kNoReturn;
      obs.mask[i] = image.mask.empty() ? valid : image.mask[i] != 0;
      if (!valid || !obs.mask[i]) continue;
      obs.points.push_back(rotation * Vec3(slope_u[size_t(u)] * z, slope_v * z, z) + camera_pose.position);
      obs.pixels.push_back(uint32_t(i));
    }
  }
  if (obs.points.empty()) {
    ThrowInvalidArgument(std::string("depth_image.depth: no pixel") + (image.mask.empty() ? "" : " inside the mask") +
                         " has a finite, positive depth");
  }
  return obs;
}

// The virtual camera of unorganized input (see observation.h).
Observation FromPoints(const std::vector<Vec3>& points, const Pose& camera_pose, size_t max_points) {
  if (points.empty()) ThrowInvalidArgument("cloud.points: the cloud is empty");
  CheckLimit("cloud.points", points.size(), "points", max_points);
  const Pose world_to_camera = camera_pose.Inverse();
  std::vector<Vec3> local(points.size());
  std::vector<double> depths(points.size());
  for (size_t i = 0; i < points.size(); ++i) {
    CheckFinite("cloud.points[" + Count(i) + "]", points[i]);
    local[i] = world_to_camera * points[i];
    if (local[i].z() <= 0) {
      ThrowInvalidArgument("cloud.points[" + Count(i) + "]: behind the camera (z = " + FormatNumber(local[i].z()) +
                           " m in the camera frame; camera_pose must be the pose the cloud was seen from)");
    }
    depths[i] = local[i].z();
  }
  std::nth_element(depths.begin(), depths.begin() + depths.size() / 2, depths.end());
  const double median_depth = depths[depths.size() / 2];
  double f = median_depth / NeighborGrid::MedianSpacing(points) * kPixelsPerSpacing;
  double umin = 1e300, umax = -1e300, vmin = 1e300, vmax = -1e300;
  for (const Vec3& p : local) {
    umin = std::min(umin, p.x() / p.z());
    umax = std::max(umax, p.x() / p.z());
    vmin = std::min(vmin, p.y() / p.z());
    vmax = std::max(vmax, p.y() / p.z());
  }
  const double extent = std::max(umax - umin, vmax - vmin);
  f = std::min(f, (kMaxDerivedSide - 2 * kDerivedMargin - 2) / std::max(extent, 1e-12));
  // A point a hair in front of the camera projects to an infinite image coordinate (found by perception_fuzz):
  // no image of finite size holds the cloud.
  if (!(f > 0) || !std::isfinite(f * (umax - umin)) || !std::isfinite(f * (vmax - vmin)) ||
      !std::isfinite(f * umin) || !std::isfinite(f * vmin)) {
    ThrowInvalidArgument("cloud.points: the points span " + FormatNumber(extent) +
                         " in the image plane as seen from camera_pose; no camera image of finite size holds them");
  }
  Observation obs;
  obs.camera_pose = camera_pose;
  obs.derived_camera = true;
  obs.points = points;
  CameraIntrinsics& k = obs.intrinsics;
  k.fx = k.fy = f;
  k.cx = kDerivedMargin - f * umin;
  k.cy = kDerivedMargin - f * vmin;
  k.width = int(std::ceil(f * (umax - umin))) + 2 * kDerivedMargin + 1;
  k.height = int(std::ceil(f * (vmax - vmin))) + 2 * kDerivedMargin + 1;
  obs.depth.assign(size_t(k.width) * k.height, kNoReturn);
  cv::Mat hit(k.height, k.width, CV_8U, cv::Scalar(0));
  for (const Vec3& p : local) {
    const int u = int(std::lround(f * p.x() / p.z() + k.cx)), v = int(std::lround(f * p.y() / p.z() + k.cy));
    float& d = obs.depth[size_t(v) * k.width + u];
    d = std::min(d, float(p.z()));
    hit.at<uint8_t>(v, u) = 1;
  }
  cv::morphologyEx(hit, hit, cv::MORPH_CLOSE, cv::getStructuringElement(cv::MORPH_RECT, {3, 3}));
  obs.mask.assign(hit.datastart, hit.dataend);
  return obs;
}

// Scanned once here for the stages that window the image around the mask.
PixelBox MaskBox(const Observation& observation) {
  const CameraIntrinsics& k = observation.intrinsics;
  PixelBox box{k.width, k.height, -1, -1};
  for (int v = 0; v < k.height; ++v) {
    // Per row its first and last mask pixel: the pixels between them are never read.
    const uint8_t* row = observation.mask.data() + size_t(v) * size_t(k.width);
    const uint8_t* end = row + k.width;
    const uint8_t* first = std::find_if(row, end, [](uint8_t m) { return m != 0; });
    if (first == end) continue;
    const uint8_t* last = end - 1;
    while (!*last) --last;  // stops at `first` at the latest
    box.u_lo = std::min(box.u_lo, int(first - row)), box.u_hi = std::max(box.u_hi, int(last - row));
    box.v_lo = std::min(box.v_lo, v), box.v_hi = v;
  }
  return box.u_hi < 0 ? PixelBox{} : box;
}

}  // namespace

bool PointsFartherApartThan(const Observation& observation, double distance) {
  if (observation.pixels.empty()) return false;
  const CameraIntrinsics& k = observation.intrinsics;
  double nearest = std::numeric_limits<double>::infinity(), slope_u = 0, slope_v = 0;
  for (uint32_t pixel : observation.pixels) {
    nearest = std::min(nearest, double(observation.depth[pixel]));
    slope_u = std::max(slope_u, std::abs(int(pixel % uint32_t(k.width)) - k.cx) / k.fx);
    slope_v = std::max(slope_v, std::abs(int(pixel / uint32_t(k.width)) - k.cy) / k.fy);
  }
  if (!(nearest > distance)) return false;
  const double reach_u = k.fx * distance * std::sqrt(1 + slope_u * slope_u) / (nearest - distance);
  const double reach_v = k.fy * distance * std::sqrt(1 + slope_v * slope_v) / (nearest - distance);
  return reach_u < 0.5 && reach_v < 0.5;  // half a pixel: room for the rounding of the points' coordinates
}

double MedianDepth(const Observation& observation, const std::vector<uint32_t>& pixels) {
  std::vector<float> depths(pixels.size());
  for (size_t i = 0; i < pixels.size(); ++i) depths[i] = observation.depth[pixels[i]];
  std::nth_element(depths.begin(), depths.begin() + depths.size() / 2, depths.end());
  return depths[depths.size() / 2];
}

Observation Observe(const PartialView& view, size_t max_points) {
  Pose pose = view.camera_pose;
  CheckPose("camera_pose", &pose);
  Observation observation =
      view.image ? FromImage(*view.image, pose, max_points) : FromPoints(view.points, pose, max_points);
  observation.mask_box = MaskBox(observation);
  return observation;
}

}  // namespace graspsim
