#include "perception/free_space.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include <opencv2/imgproc.hpp>

namespace graspsim {
namespace {

constexpr float kNoDepth = std::numeric_limits<float>::infinity();

}  // namespace

SeenFreeSpace::SeenFreeSpace(const Observation& observation, double margin_px, double depth_margin)
    : intrinsics_(observation.intrinsics),
      world_to_camera_(observation.camera_pose.Inverse()),
      depth_margin_(depth_margin) {
  const CameraIntrinsics& k = observation.intrinsics;
  // Only a window around the mask needs its distance: every pixel outside the window is beyond the margin.
  const auto [u_lo, v_lo, u_hi, v_hi] = observation.mask_box;
  const int pad = int(std::ceil(std::max(margin_px, 0.0))) + 1;
  window_.x = std::max(0, u_lo - pad);
  window_.y = std::max(0, v_lo - pad);
  if (u_hi < 0) return;  // no mask: every pixel is beyond it
  window_.width = std::min(k.width - 1, u_hi + pad) - window_.x + 1;
  window_.height = std::min(k.height - 1, v_hi + pad) - window_.y + 1;
  cv::Mat not_mask(window_.height, window_.width, CV_8U);
  for (int v = 0; v < window_.height; ++v) {
    const uint8_t* mask = observation.mask.data() + size_t(v + window_.y) * k.width + window_.x;
    for (int u = 0; u < window_.width; ++u) not_mask.at<uint8_t>(v, u) = mask[u] ? 0 : 255;
  }
  cv::Mat distance;  // to the nearest mask pixel, px; 0 on the mask
  cv::distanceTransform(not_mask, distance, cv::DIST_L2, cv::DIST_MASK_PRECISE);
  // Per window pixel: beyond the margin, or the depth to test against: the least depth of the mask pixels within the
  // margin (at least the 3 × 3 around it). On the mask a pixel's centre ray is not a point's ray: across a grazing
  // face the depth changes by several millimetres within a pixel. Beside the mask the object cannot stand before
  // its own silhouette's edge. +inf where no depth was seen.
  const int reach = std::max(1, pad - 1);
  const double reach_sq = std::max(2.0, margin_px * margin_px);
  cv::Mat kernel(2 * reach + 1, 2 * reach + 1, CV_8U);
  for (int dv = -reach; dv <= reach; ++dv) {
    for (int du = -reach; du <= reach; ++du) kernel.at<uint8_t>(dv + reach, du + reach) = du * du + dv * dv <= reach_sq;
  }
  cv::Mat depth(window_.height, window_.width, CV_32F);
  for (int v = 0; v < window_.height; ++v) {
    const size_t row = size_t(v + window_.y) * k.width + window_.x;
    for (int u = 0; u < window_.width; ++u) {
      depth.at<float>(v, u) = observation.mask[row + u] ? observation.depth[row + u] : kNoDepth;
    }
  }
  cv::Mat least;  // the minimum over the kernel (erosion), +inf padding past the window's edge
  cv::erode(depth, least, kernel, {-1, -1}, 1, cv::BORDER_CONSTANT, cv::Scalar(kNoDepth));
  near_depth_.resize(size_t(window_.width) * window_.height);
  for (int v = 0; v < window_.height; ++v) {
    for (int u = 0; u < window_.width; ++u) {
      const bool beyond = distance.at<float>(v, u) > margin_px;
      near_depth_[size_t(v) * window_.width + u] = beyond ? kBeyond : least.at<float>(v, u);
    }
  }
}

bool SeenFreeSpace::Contains(const Vec3& world_point) const {
  const Vec3 p = world_to_camera_ * world_point;
  if (!(p.z() > 0)) return false;
  const CameraIntrinsics& k = intrinsics_;
  const double u = std::round(k.fx * p.x() / p.z() + k.cx), v = std::round(k.fy * p.y() / p.z() + k.cy);
  if (!(u >= 0 && v >= 0 && u < k.width && v < k.height)) return false;
  const int wu = int(u) - window_.x, wv = int(v) - window_.y;
  if (wu < 0 || wv < 0 || wu >= window_.width || wv >= window_.height) return true;
  const float depth = near_depth_[size_t(wv) * window_.width + wu];
  return depth == kBeyond || (std::isfinite(depth) && p.z() < double(depth) - depth_margin_);
}

}  // namespace graspsim
