#include "perception/symmetry_search.h"

#include <algorithm>
#include <cmath>
#include <string>

#include <Eigen/Eigenvalues>
#include <opencv2/imgproc.hpp>

#include "core/error.h"
#include "core/format.h"
#include "core/validate.h"

namespace graspsim {
namespace {

constexpr double kDegree = M_PI / 180;
// A later hypothesis replaces the best only when it is lower by more than this fraction (see the header, 2.).
// Scores are mean penalties per mirrored point (px²); differences below this are pixel rounding, not evidence.
constexpr double kTieTolerance = 2e-3;
// A table-projected cloud this close to isotropic (minor / major eigenvalue) has no meaningful eigenvectors (a
// cylinder seen from above and the side projects to a disc): the initial plane then faces the camera.
constexpr double kIsotropic = 0.8;

void CheckCount(const std::string& field, int value, int lo, int hi) {
  if (value < lo || value > hi) {
    ThrowInvalidArgument(field + ": " + std::to_string(value) + " is outside " + std::to_string(lo) + ".." +
                         std::to_string(hi));
  }
}

void CheckRange(const std::string& field, double value, double lo, double hi) {
  CheckFinite(field, value);
  if (value < lo || value > hi) {
    ThrowInvalidArgument(field + ": " + FormatNumber(value) + " is outside " + FormatNumber(lo) + ".." +
                         FormatNumber(hi));
  }
}

// Values lo + i (hi − lo) / (count − 1), or the middle for one.
std::vector<double> Steps(double lo, double hi, int count) {
  std::vector<double> out;
  for (int i = 0; i < count; ++i) out.push_back(count == 1 ? 0.5 * (lo + hi) : lo + (hi - lo) * i / (count - 1));
  return out;
}

// Orientations nearest the window's centre first (positive before negative), so a tie keeps the nearer one.
std::vector<double> AnglesByDistance(double centre, double half, int count) {
  std::vector<double> out = Steps(centre - half, centre + half, count);
  std::stable_sort(out.begin(), out.end(), [centre](double a, double b) {
    const double da = std::abs(a - centre), db = std::abs(b - centre);
    if (std::abs(da - db) > 1e-12) return da < db;
    return a > b;
  });
  return out;
}

// The observed depth at (u, v): bilinear between the four pixels around it when all four saw the object (a slanted
// surface changes depth by millimetres from one pixel to the next, which rounding would turn into false
// penalties), else the nearest pixel's.
double ObservedDepth(const Observation& obs, double u, double v, size_t nearest) {
  const CameraIntrinsics& k = obs.intrinsics;
  const double u0 = std::floor(u), v0 = std::floor(v);
  if (u0 < 0 || v0 < 0 || u0 + 1 >= k.width || v0 + 1 >= k.height) return obs.depth[nearest];
  const size_t i = size_t(v0) * size_t(k.width) + size_t(u0), w = size_t(k.width);
  const float d00 = obs.depth[i], d10 = obs.depth[i + 1], d01 = obs.depth[i + w], d11 = obs.depth[i + w + 1];
  if (!obs.mask[i] || !obs.mask[i + 1] || !obs.mask[i + w] || !obs.mask[i + w + 1] ||
      !std::isfinite(d00 + d10 + d01 + d11)) {
    return obs.depth[nearest];
  }
  const double fu = u - u0, fv = v - v0;
  return (1 - fv) * ((1 - fu) * d00 + fu * d10) + fv * ((1 - fu) * d01 + fu * d11);
}

}  // namespace

void ValidateSymmetryParams(const SymmetryParams& p) {
  CheckFinite("table_normal", p.table_normal);
  if (p.table_normal.norm() < 1e-9) ThrowInvalidArgument("table_normal: zero length");
  CheckCount("orientations", p.orientations, 1, 50);
  CheckCount("shifts", p.shifts, 1, 50);
  CheckCount("refinements", p.refinements, 0, 5);
  if (p.fine_shifts != 0) CheckCount("fine_shifts", p.fine_shifts, 2, 100);
  CheckRange("max_angle_deg", p.max_angle_deg, 0, 90);
  CheckRange("shift_range", p.shift_range, 0, 4);
  CheckRange("depth_tolerance", p.depth_tolerance, 0, 1);
  if (p.score_points != 0) CheckCount("score_points", p.score_points, 50, 100000);
}

Vec3 MirrorPoint(const SymmetryPlane& plane, const Vec3& p) {
  return p - 2 * (p - plane.point).dot(plane.normal) * plane.normal;
}

Vec3 MirrorDirection(const SymmetryPlane& plane, const Vec3& d) { return d - 2 * d.dot(plane.normal) * plane.normal; }

SymmetrySearch::SymmetrySearch(const Observation& observation) : observation_(observation) {
  const CameraIntrinsics& k = observation.intrinsics;
  auto [lo_x, lo_y, hi_x, hi_y] = observation.mask_box;
  if (hi_x < 0) lo_x = hi_x = lo_y = hi_y = 0;  // no mask pixel (Observe refuses that): a one-pixel window
  const int margin = std::max({16, (hi_x - lo_x + 1) / 2, (hi_y - lo_y + 1) / 2});
  x0_ = std::max(0, lo_x - margin), y0_ = std::max(0, lo_y - margin);
  w_ = std::min(k.width, hi_x + margin + 1) - x0_, h_ = std::min(k.height, hi_y + margin + 1) - y0_;
  cv::Mat outside(h_, w_, CV_8U);
  for (int y = 0; y < h_; ++y) {
    const uint8_t* row = observation.mask.data() + size_t(y + y0_) * size_t(k.width) + x0_;
    for (int x = 0; x < w_; ++x) outside.at<uint8_t>(y, x) = row[x] ? 0 : 255;
  }
  cv::Mat distance;
  cv::distanceTransform(outside, distance, cv::DIST_L2, cv::DIST_MASK_PRECISE, CV_32F);
  outside_sq_.resize(size_t(w_) * size_t(h_));
  for (int y = 0; y < h_; ++y) {
    for (int x = 0; x < w_; ++x) {
      const float d = distance.at<float>(y, x);
      outside_sq_[size_t(y) * w_ + x] = d * d;
    }
  }
}

double SymmetrySearch::Score(const std::vector<Vec3>& points, const SymmetryPlane& plane,
                             double depth_tolerance) const {
  const Observation& obs = observation_;
  const CameraIntrinsics& k = obs.intrinsics;
  // Mirror then world → camera as one affine map: c = A p + b.
  const Pose to_camera = obs.camera_pose.Inverse();
  const Mat3 rotation = to_camera.orientation.toRotationMatrix();
  const Mat3 householder = Mat3::Identity() - 2 * plane.normal * plane.normal.transpose();
  const Mat3 a = rotation * householder;
  const Vec3 b = rotation * (2 * plane.point.dot(plane.normal) * plane.normal) + to_camera.position;
  const double beyond = double(k.width) * k.width + double(k.height) * k.height;  // behind the camera
  double sum_out = 0, sum_in = 0;
  size_t n_out = 0, n_in = 0;
  for (const Vec3& p : points) {
    const Vec3 c = a * p + b;
    if (c.z() <= 1e-9) {
      sum_out += beyond;
      ++n_out;
      continue;
    }
    const double u = k.fx * c.x() / c.z() + k.cx, v = k.fy * c.y() / c.z() + k.cy;
    // Rounded to the window (every mask pixel lies inside it); beyond, its edge value plus the overshoot².
    const double ur = std::round(u) - x0_, vr = std::round(v) - y0_;
    const double uc = std::clamp(ur, 0.0, double(w_ - 1)), vc = std::clamp(vr, 0.0, double(h_ - 1));
    const double overshoot = (ur - uc) * (ur - uc) + (vr - vc) * (vr - vc);
    const size_t pixel = (size_t(vc) + y0_) * size_t(k.width) + size_t(uc) + x0_;
    if (overshoot == 0 && obs.mask[pixel]) {
      ++n_in;
      const double in_front = ObservedDepth(obs, u, v, pixel) - c.z() - depth_tolerance;
      if (in_front > 0) sum_in += in_front * k.fx / c.z();
    } else {
      ++n_out;
      sum_out += outside_sq_[size_t(vc) * size_t(w_) + size_t(uc)] + overshoot;
    }
  }
  // Both sums over every mirrored point (see the header: eq. 3's per-subset means jump when one point crosses).
  return points.empty() ? 0 : (sum_out + sum_in) / double(n_out + n_in);
}

SymmetryPlane SymmetrySearch::Find(const std::vector<Vec3>& points, const SymmetryParams& params) const {
  ValidateSymmetryParams(params);
  if (points.size() < 3) ThrowInvalidArgument("points: " + std::to_string(points.size()) + " points; need 3");
  const Vec3 up = params.table_normal.normalized();
  const Vec3 ax = (std::abs(up.x()) < 0.9 ? Vec3::UnitX() : Vec3::UnitY()).cross(up).normalized();
  const Vec3 ay = up.cross(ax);

  // 1. The table-projected cloud: centroid and eigenvectors.
  Vec3 centroid = Vec3::Zero();
  for (const Vec3& p : points) centroid += p;
  centroid /= double(points.size());
  Eigen::Matrix2d covariance = Eigen::Matrix2d::Zero();
  for (const Vec3& p : points) {
    const Eigen::Vector2d q((p - centroid).dot(ax), (p - centroid).dot(ay));
    covariance += q * q.transpose();
  }
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> eigen(covariance);
  const Eigen::Vector2d minor = eigen.eigenvectors().col(0), major = eigen.eigenvectors().col(1);
  const Vec3 e_minor = minor.x() * ax + minor.y() * ay, e_major = major.x() * ax + major.y() * ay;
  Vec3 view = centroid - observation_.CameraCentre();
  view -= view.dot(up) * up;
  // The plane's normal is the eigenvector most parallel to the view (the axis the one most perpendicular to it);
  // seen from straight above, the minor one (the plane along the object's length).
  Vec3 n0 = view.norm() > 1e-9 && std::abs(e_major.dot(view)) > std::abs(e_minor.dot(view)) ? e_major : e_minor;
  const Eigen::Vector2d spread = eigen.eigenvalues();
  if (view.norm() > 1e-9 && spread(0) >= kIsotropic * spread(1)) n0 = view.normalized();
  if (n0.dot(view) < 0) n0 = -n0;

  // 2. Shifts up to shift_range × the farthest seen point behind the centroid.
  double reach = 0;
  for (const Vec3& p : points) reach = std::max(reach, (p - centroid).dot(n0));
  const double max_shift = params.shift_range * reach;
  // The points the hypotheses are scored on: every stride-th (see score_points).
  const size_t stride = params.score_points > 0
                            ? (points.size() + size_t(params.score_points) - 1) / size_t(params.score_points) : 1;
  std::vector<Vec3> subset;
  if (stride > 1) {
    subset.reserve(points.size() / stride + 1);
    for (size_t i = 0; i < points.size(); i += stride) subset.push_back(points[i]);
  }
  const std::vector<Vec3>& scored = stride > 1 ? subset : points;

  const auto plane_at = [&](double alpha, double shift) {
    SymmetryPlane plane;
    plane.normal = std::cos(alpha) * n0 + std::sin(alpha) * up.cross(n0);
    plane.point = centroid + shift * plane.normal;
    plane.angle_deg = alpha / kDegree;
    plane.shift = shift;
    return plane;
  };
  int hypotheses = 0;
  // Scores one hypothesis (3. and 4.); it replaces *winner only when lower by more than the tie tolerance.
  const auto try_plane = [&](double alpha, double shift, SymmetryPlane* winner) {
    SymmetryPlane plane = plane_at(alpha, shift);
    plane.score = Score(scored, plane, params.depth_tolerance);
    ++hypotheses;
    if (plane.score < winner->score - kTieTolerance || !std::isfinite(winner->score)) *winner = plane;
  };
  double angle_half = params.max_angle_deg * kDegree, angle_centre = 0;
  double shift_lo = 0, shift_hi = max_shift;
  SymmetryPlane best;
  best.score = INFINITY;
  for (int pass = 0; pass <= params.refinements; ++pass) {
    for (double alpha : AnglesByDistance(angle_centre, angle_half, params.orientations)) {
      for (double shift : Steps(shift_lo, shift_hi, params.shifts)) try_plane(alpha, shift, &best);
    }
    // 5. The next pass spans ± one step of this one around the best.
    const double angle_step = params.orientations > 1 ? 2 * angle_half / (params.orientations - 1) : angle_half;
    const double shift_step = params.shifts > 1 ? (shift_hi - shift_lo) / (params.shifts - 1) : 0.5 * (shift_hi - shift_lo);
    // Windows stay inside the paper's ranges (an object symmetric about many planes would otherwise drift).
    const double max_angle = params.max_angle_deg * kDegree;
    angle_half = angle_step;
    angle_centre = std::clamp(best.angle_deg * kDegree, -max_angle + angle_half, max_angle - angle_half);
    if (angle_half > max_angle) angle_centre = 0, angle_half = max_angle;
    shift_lo = std::max(0.0, best.shift - shift_step);
    shift_hi = std::min(max_shift, best.shift + shift_step);
  }
  // 6. The shift alone, finer, at the best orientation: across ± one step of the last pass, nearest first, its own
  // best taken when it is no worse than the grid's (within the tie tolerance: a nearer plane then wins).
  if (params.fine_shifts > 0) {
    SymmetryPlane fine_best;
    fine_best.score = INFINITY;
    const double alpha = best.angle_deg * kDegree;
    for (double shift : Steps(shift_lo, shift_hi, params.fine_shifts)) try_plane(alpha, shift, &fine_best);
    if (fine_best.score <= best.score + kTieTolerance) best = fine_best;
  }
  best.hypotheses = hypotheses;
  return best;
}

}  // namespace graspsim
