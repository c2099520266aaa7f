#include "perception/normals.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <string>

#include <Eigen/Eigenvalues>

#include "core/error.h"
#include "core/format.h"
#include "core/validate.h"
#include "perception/image_neighbors.h"
#include "perception/neighbor_grid.h"

namespace graspsim {

namespace {

void CheckNormalInput(const std::vector<Vec3>& points, const NormalEstimationParams& params) {
  if (points.size() < 3) {
    ThrowInvalidArgument("points: " + std::to_string(points.size()) + " points; a plane fit needs at least 3");
  }
  if (params.k < 3 || params.k > 100) {
    ThrowInvalidArgument("k: " + std::to_string(params.k) + " is outside 3..100");
  }
  CheckFinite("viewpoint", params.viewpoint);
  for (size_t i = 0; i < points.size(); ++i) {
    if (!points[i].allFinite()) CheckFinite("points[" + std::to_string(i) + "]", points[i]);  // names only a bad one
  }
}

// The smallest eigenvector of a 3 × 3 covariance (the direction of least spread), facing the viewpoint from `at`,
// in closed form: about 3× faster than Eigen's iterative solver; the smallest eigenvector of a neighbourhood this
// flat is well separated, and the covariances here are of coordinates relative to a nearby point (or to the
// cloud's mean, a few centimetres away), so few digits are lost.
Vec3 LeastSpreadClosedForm(const Mat3& covariance, const Vec3& at, const Vec3& viewpoint) {
  Eigen::SelfAdjointEigenSolver<Mat3> eigen;
  eigen.computeDirect(covariance);
  Vec3 n = eigen.eigenvectors().col(0);  // eigenvalues ascending
  if (n.dot(viewpoint - at) < 0) n = -n;
  return n.normalized();
}

// The same, by power iteration where it settles quickly.
Vec3 LeastSpreadTowards(const Mat3& covariance, const Vec3& at, const Vec3& viewpoint, const Vec3* guess = nullptr) {
  // First, power iteration on the adjugate squared (the adjugate's dominant eigenvector is the covariance's least
  // one, and it needs no inverse), from `guess` (a neighbouring window's normal) or the direction to the viewpoint:
  // the camera saw the surface, so the oriented normal is within 90° of that, and the iteration (all eigenvalues
  // positive) stays on the side it starts. Each step shrinks the error by (λ_min / λ_mid)², ~0.01–0.1 on a surface
  // patch: one to four steps, a fraction of the closed form's cost (its acos, cos and sin). A patch not flat enough
  // to settle in 6 steps takes the closed form.
  const Mat3& c = covariance;
  Mat3 adjugate;
  adjugate(0, 0) = c(1, 1) * c(2, 2) - c(1, 2) * c(1, 2);
  adjugate(1, 1) = c(0, 0) * c(2, 2) - c(0, 2) * c(0, 2);
  adjugate(2, 2) = c(0, 0) * c(1, 1) - c(0, 1) * c(0, 1);
  adjugate(0, 1) = adjugate(1, 0) = c(0, 2) * c(1, 2) - c(0, 1) * c(2, 2);
  adjugate(0, 2) = adjugate(2, 0) = c(0, 1) * c(1, 2) - c(0, 2) * c(1, 1);
  adjugate(1, 2) = adjugate(2, 1) = c(0, 1) * c(0, 2) - c(0, 0) * c(1, 2);
  Mat3 squared = adjugate * adjugate;
  // Scaled so its eigenvalues are at most 1 (the trace bounds them): the iterate then needs no normalizing per step
  // (a square root and a division, most of this function's time), and neither grows nor vanishes.
  const double trace = squared.trace();
  if (!(trace > 0) || !std::isfinite(trace)) return LeastSpreadClosedForm(covariance, at, viewpoint);
  squared *= 1 / trace;
  const Vec3 towards = viewpoint - at;
  Vec3 n = guess && guess->dot(towards) > 0 ? *guess : towards.normalized();
  for (int step = 0; step < 6; ++step) {
    const Vec3 next = squared * n;
    // Settled when the direction turned by under 1e-3 rad (far below the fit's noise, ~3°): cos² of the turn
    // above 1 − 1e-6, without a square root.
    const double along = next.dot(n);
    const bool settled = along > 0 && along * along >= (1 - 1e-6) * next.squaredNorm() * n.squaredNorm();
    n = next;
    if (settled) return n.normalized();
  }
  return LeastSpreadClosedForm(covariance, at, viewpoint);
}

Vec3 PlaneFitNormal(const std::vector<Vec3>& points, uint32_t i, const std::vector<uint32_t>& neighbours,
                    const Vec3& viewpoint) {
  // Covariance about the neighbours' mean, accumulated relative to the query point to keep the digits.
  Vec3 mean = Vec3::Zero();
  for (uint32_t j : neighbours) mean += points[j] - points[i];
  mean /= double(neighbours.size());
  Mat3 covariance = Mat3::Zero();
  for (uint32_t j : neighbours) {
    const Vec3 d = points[j] - points[i] - mean;
    covariance += d * d.transpose();
  }
  return LeastSpreadTowards(covariance, points[i], viewpoint);
}

// EstimateNormals once its input is checked.
std::vector<Vec3> PlaneFitNormals(const std::vector<Vec3>& points, const CloudNeighbors& neighbors,
                                  const NormalEstimationParams& params) {
  std::vector<Vec3> normals(points.size());
  std::vector<uint32_t> neighbours;
  for (size_t i = 0; i < points.size(); ++i) {
    neighbors.NearestTo(uint32_t(i), params.k, &neighbours);
    normals[i] = PlaneFitNormal(points, uint32_t(i), neighbours, params.viewpoint);
  }
  return normals;
}

}  // namespace

std::vector<Vec3> EstimateNormals(const std::vector<Vec3>& points, const NormalEstimationParams& params) {
  CheckNormalInput(points, params);
  return PlaneFitNormals(points, NeighborGrid(points, NeighborGrid::SuggestCellSize(points, params.k)), params);
}

std::vector<Vec3> EstimateNormals(const std::vector<Vec3>& points, const CloudNeighbors& neighbors,
                                  const NormalEstimationParams& params) {
  CheckNormalInput(points, params);
  return PlaneFitNormals(points, neighbors, params);
}

std::vector<Vec3> EstimateImageNormals(const Observation& observation, const std::vector<Vec3>& points,
                                       const std::vector<uint32_t>& pixels, double radius_m, double depth_m,
                                       const Vec3& viewpoint) {
  NormalEstimationParams fallback;
  fallback.viewpoint = viewpoint;
  CheckNormalInput(points, fallback);
  CheckFinite("radius_m", radius_m);
  if (!(radius_m > 0)) ThrowInvalidArgument("radius_m: " + FormatNumber(radius_m) + " must be positive");
  if (!(depth_m > 0)) ThrowInvalidArgument("depth_m: " + FormatNumber(depth_m) + " must be positive");
  if (pixels.size() != points.size()) {
    ThrowInvalidArgument("pixels: " + std::to_string(pixels.size()) + " for " + std::to_string(points.size()) +
                         " points");
  }
  const CameraIntrinsics& cam = observation.intrinsics;
  // One window for the view: radius_m at depth_m.
  const double pixels_per_m = std::max(cam.fx, cam.fy) / depth_m;
  const int r = int(std::lround(std::clamp(radius_m * pixels_per_m, 1.0, 256.0)));  // clamped before rounding: a
                                                                                      // focal length may be huge
  // Moments relative to the cloud's mean (m) so the covariances keep their digits.
  Vec3 centre = Vec3::Zero();
  for (const Vec3& p : points) centre += p;
  centre /= double(points.size());
  const PixelIndex index(cam.width, pixels);
  const int box_w = index.width, box_h = index.height;
  const std::vector<int32_t>& point_at = index.point_at;
  // Window sums by sliding: per column the sum over the window's rows (updated a row at a time), then along each
  // row the sum of the window's columns. O(1) per pixel, memory per column only.
  using Moments = std::array<double, 10>;  // count, x, y, z, xx, xy, xz, yy, yz, zz
  const auto add_row = [&](std::vector<Moments>* columns, int v, double sign) {
    for (int u = 0; u < box_w; ++u) {
      const int32_t i = point_at[size_t(v) * box_w + u];
      if (i < 0) continue;
      const Vec3 p = points[i] - centre;
      const double m[10] = {1, p.x(), p.y(), p.z(), p.x() * p.x(), p.x() * p.y(), p.x() * p.z(),
                            p.y() * p.y(), p.y() * p.z(), p.z() * p.z()};
      Moments& column = (*columns)[u];
      for (int c = 0; c < 10; ++c) column[c] += sign * m[c];
    }
  };
  std::vector<Moments> columns(box_w, Moments{});
  for (int v = 0; v < std::min(r, box_h); ++v) add_row(&columns, v, 1);

  // A window 9 or more pixels wide shares all but one of its columns with the previous pixel's along the row: where
  // that pixel's normal was solved, every other point takes it (a turn of a fraction of a degree against the fit's
  // noise of ~3°, normals_test.cpp) instead of solving again.
  const bool share_along_rows = r >= 4;
  std::vector<Vec3> normals(points.size());
  std::vector<uint32_t> sparse;  // windows with fewer than 3 points
  for (int v = 0; v < box_h; ++v) {
    if (v + r < box_h) add_row(&columns, v + r, 1);
    Moments window{};
    const Vec3* previous = nullptr;
    int previous_u = -2;
    for (int u = 0; u < std::min(r, box_w); ++u) {
      for (int c = 0; c < 10; ++c) window[c] += columns[u][c];
    }
    for (int u = 0; u < box_w; ++u) {
      if (u + r < box_w) {
        for (int c = 0; c < 10; ++c) window[c] += columns[u + r][c];
      }
      const int32_t i = point_at[size_t(v) * box_w + u];
      if (i >= 0) {
        const double n = window[0];
        if (n < 2.5) {
          sparse.push_back(uint32_t(i));
        } else if (share_along_rows && (u & 1) && previous_u == u - 1 && previous->dot(viewpoint - points[i]) > 0) {
          normals[i] = *previous;
        } else {
          const Vec3 mean = Vec3(window[1], window[2], window[3]) / n;
          Mat3 covariance;
          covariance << window[4], window[5], window[6], window[5], window[7], window[8], window[6], window[8],
              window[9];
          covariance = covariance / n - mean * mean.transpose();
          // The previous window along the row overlaps this one but for a column: its normal is the start.
          normals[i] = LeastSpreadTowards(covariance, points[i], viewpoint, previous);
          previous = &normals[i];
          previous_u = u;
        }
      }
      if (u - r >= 0) {
        for (int c = 0; c < 10; ++c) window[c] -= columns[u - r][c];
      }
    }
    if (v - r >= 0) add_row(&columns, v - r, -1);
  }
  if (!sparse.empty()) {
    const NeighborGrid grid(points, NeighborGrid::SuggestCellSize(points, fallback.k));
    std::vector<uint32_t> neighbours;
    for (uint32_t i : sparse) {
      grid.Nearest(points[i], fallback.k, &neighbours);
      normals[i] = PlaneFitNormal(points, i, neighbours, viewpoint);
    }
  }
  return normals;
}

}  // namespace graspsim
