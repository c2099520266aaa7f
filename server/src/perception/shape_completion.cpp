#include "perception/shape_completion.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <string>

#include <Eigen/Eigenvalues>
#include <opencv2/imgproc.hpp>

#include "core/error.h"
#include "perception/cloud_filters.h"
#include "perception/neighbor_grid.h"
#include "perception/normals.h"

namespace graspsim {
namespace {

using Clock = std::chrono::steady_clock;

double MsSince(Clock::time_point start) {
  return std::chrono::duration<double, std::milli>(Clock::now() - start).count();
}

// The stages need a surface: at least 10 points that span a plane, not a line.
void CheckSpread(const std::vector<Vec3>& points, size_t input_points) {
  const std::string what = std::to_string(points.size()) + " of " + std::to_string(input_points) + " points";
  if (points.size() < 10) ThrowInvalidArgument("points: " + what + " left after the outlier filter; need 10");
  Vec3 mean = Vec3::Zero();
  for (const Vec3& p : points) mean += p;
  mean /= double(points.size());
  Mat3 covariance = Mat3::Zero();
  for (const Vec3& p : points) covariance += (p - mean) * (p - mean).transpose();
  const Vec3 spread = Eigen::SelfAdjointEigenSolver<Mat3>(covariance, Eigen::EigenvaluesOnly).eigenvalues();
  if (!(spread(1) > 1e-12 * spread(2))) ThrowInvalidArgument("points: all " + what + " lie on one line");
}

// Filter: voxels (given, or automatic above target_points), then statistical outliers. Voxels first: the outlier
// test then runs on ~1.5k points instead of 39k, and an isolated outlier stays alone in its voxel, still isolated.
std::vector<Vec3> FilterCloud(const std::vector<Vec3>& points, const CompletionOptions& options) {
  double voxel = options.voxel_size;
  std::vector<Vec3> merged;
  if (voxel > 0) {
    merged = VoxelDownsample(points, voxel);
  } else if (options.target_points > 0 && points.size() > options.target_points) {
    // A first guess from the spacing (noise makes the nearest neighbour closer than the surface's sampling, so it
    // overshoots the count), then one correction by the count it gave.
    const double target = double(options.target_points);
    voxel = NeighborGrid::MedianSpacing(points) * std::sqrt(1.5 * double(points.size()) / target);
    merged = VoxelDownsample(points, voxel);
    if (double(merged.size()) > 1.2 * target) merged = VoxelDownsample(points, voxel * std::sqrt(merged.size() / target));
  }
  const std::vector<Vec3>& cloud = merged.empty() ? points : merged;
  return options.outlier_std > 0 ? RemoveStatisticalOutliers(cloud, options.outlier_k, options.outlier_std) : cloud;
}

// Normals: the seen points' towards the camera; each mirrored point takes its source's normal reflected.
void OrientedSurfacePoints(const std::vector<Vec3>& seen, const std::optional<SymmetryPlane>& plane,
                           const Vec3& camera, int k, std::vector<Vec3>* points, std::vector<Vec3>* normals) {
  NormalEstimationParams params;
  params.k = k;
  params.viewpoint = camera;
  *normals = EstimateNormals(seen, params);
  *points = seen;
  if (!plane) return;
  points->reserve(2 * seen.size());
  normals->reserve(2 * seen.size());
  for (size_t i = 0; i < seen.size(); ++i) {
    points->push_back(MirrorPoint(*plane, seen[i]));
    normals->push_back(MirrorDirection(*plane, (*normals)[i]));
  }
}

// The underside on a known table: points every `step` (the seen cloud's spacing) over the convex hull of the
// footprint, normals into the table.
void AddTableCap(const Vec3& up, double offset, double step, std::vector<Vec3>* points, std::vector<Vec3>* normals) {
  const Vec3 ax = (std::abs(up.x()) < 0.9 ? Vec3::UnitX() : Vec3::UnitY()).cross(up).normalized();
  const Vec3 ay = up.cross(ax);
  std::vector<cv::Point2f> footprint, hull;
  footprint.reserve(points->size());
  for (const Vec3& p : *points) footprint.emplace_back(float(p.dot(ax)), float(p.dot(ay)));
  cv::convexHull(footprint, hull, /*clockwise=*/false);
  if (hull.size() < 3) return;
  double lo_x = hull[0].x, hi_x = lo_x, lo_y = hull[0].y, hi_y = lo_y;
  for (const cv::Point2f& h : hull) {
    lo_x = std::min<double>(lo_x, h.x), hi_x = std::max<double>(hi_x, h.x);
    lo_y = std::min<double>(lo_y, h.y), hi_y = std::max<double>(hi_y, h.y);
  }
  const auto inside = [&hull](double x, double y) {  // left of every counter-clockwise hull edge
    for (size_t i = 0; i < hull.size(); ++i) {
      const cv::Point2f a = hull[i], b = hull[(i + 1) % hull.size()];
      if ((b.x - a.x) * (y - a.y) - (b.y - a.y) * (x - a.x) < 0) return false;
    }
    return true;
  };
  for (double x = lo_x + 0.5 * step; x < hi_x; x += step) {
    for (double y = lo_y + 0.5 * step; y < hi_y; y += step) {
      if (!inside(x, y)) continue;
      points->push_back(x * ax + y * ay + offset * up);
      normals->push_back(-up);
    }
  }
}

}  // namespace

std::optional<CompletionResult> CompleteShape(const PartialView& view, const CompletionOptions& options,
                                              const CompletionProgress& progress) {
  const auto report = [&](const char* stage, double fraction) { return !progress || progress(stage, fraction); };
  const Clock::time_point start = Clock::now();
  ValidateSymmetryParams(options.symmetry);
  if (!(options.outlier_std >= 0)) ThrowInvalidArgument("outlier_std: must be ≥ 0 (0 = off)");
  if (options.table_offset && !std::isfinite(*options.table_offset)) {
    ThrowInvalidArgument("table_pose: the table's offset is not finite");
  }
  if (!(options.voxel_size >= 0)) ThrowInvalidArgument("voxel_size: must be ≥ 0 m (0 = off)");
  CompletionResult result;

  Clock::time_point t = Clock::now();
  const Observation observation = Observe(view, options.max_points);
  result.input_points = observation.points.size();
  result.ms.observe_ms = MsSince(t);
  if (!report("filter", 0.05)) return std::nullopt;

  t = Clock::now();
  const std::vector<Vec3> seen = FilterCloud(observation.points, options);
  CheckSpread(seen, observation.points.size());
  result.filtered_points = seen.size();
  result.ms.filter_ms = MsSince(t);

  if (options.method == CompletionMethod::kDelaunay) {
    if (!report("surface", 0.5)) return std::nullopt;
    t = Clock::now();
    result.mesh = DelaunayBaseline(seen, observation.camera_pose, options.delaunay);
    result.surface_points = std::min<size_t>(seen.size(), size_t(options.delaunay.samples));
    result.ms.surface_ms = MsSince(t);
    result.ms.total_ms = MsSince(start);
    return result;
  }

  if (!report("symmetry", 0.15)) return std::nullopt;
  t = Clock::now();
  result.plane = SymmetrySearch(observation).Find(seen, options.symmetry);
  result.ms.symmetry_ms = MsSince(t);

  if (!report("normals", 0.4)) return std::nullopt;
  t = Clock::now();
  std::vector<Vec3> points, normals;
  OrientedSurfacePoints(seen, result.plane, observation.CameraCentre(), options.normal_k, &points, &normals);
  if (options.table_offset) {
    AddTableCap(options.symmetry.table_normal.normalized(), *options.table_offset, NeighborGrid::MedianSpacing(seen),
                &points, &normals);
  }
  result.surface_points = points.size();
  result.ms.normals_ms = MsSince(t);

  if (!report("surface", 0.55)) return std::nullopt;
  t = Clock::now();
  PoissonResult surface = ReconstructSurface(points, normals, options.poisson);
  result.mesh = std::move(surface.mesh);
  result.poisson = surface.stats;
  result.ms.surface_ms = MsSince(t);
  result.ms.total_ms = MsSince(start);
  return result;
}

}  // namespace graspsim
