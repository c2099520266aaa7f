#include "perception/shape_completion.h"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <memory>
#include <string>

#include <opencv2/imgproc.hpp>

#include "core/error.h"
#include "perception/cloud_filters.h"
#include "perception/free_space.h"
#include "perception/image_neighbors.h"
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
  const Vec3 spread = SpreadEigenvalues(points);
  if (!(spread(1) > 1e-12 * spread(2))) ThrowInvalidArgument("points: all " + what + " lie on one line");
}

// The seen points after the filter, with the pixel each was seen at while the filter has kept the points as they
// were (organized input, no cube merging two points): their neighbours are then searched in the image.
struct SeenCloud {
  std::vector<Vec3> points;
  std::vector<uint32_t> pixels;  // empty: unorganized from here on
  double median_depth = 0;       // of the pixels, m (MedianDepth), when there are pixels

  std::unique_ptr<CloudNeighbors> Neighbors(const Observation& observation, int k) const {
    if (!pixels.empty()) {
      return std::make_unique<ImageNeighbors>(observation.intrinsics, points, pixels, ImageNeighbors::RadiusFor(k));
    }
    return std::make_unique<NeighborGrid>(points, NeighborGrid::SuggestCellSize(points, k));
  }
};

// About `target` points spread evenly over the surface that `points` sample every `spacing` (m): their means per
// voxel, the voxel from the spacing (n points every s cover n s², which cubes of side v cut into ≈ 1.5 n s² / v²),
// then one correction by the count it gave (noise makes the nearest neighbour closer than the surface's sampling,
// so the guess overshoots the count).
std::vector<Vec3> EvenlySpread(const std::vector<Vec3>& points, double spacing, size_t target) {
  const double wanted = double(target);
  const double voxel = spacing * std::sqrt(1.5 * double(points.size()) / wanted);
  std::vector<Vec3> spread = VoxelDownsample(points, voxel);
  if (double(spread.size()) > 1.2 * wanted) spread = VoxelDownsample(points, voxel * std::sqrt(spread.size() / wanted));
  return spread;
}

// Filter: voxels (given, or automatic above target_points), then statistical outliers. Voxels first: the outlier
// test then runs on ~1.5k points instead of 39k, and an isolated outlier stays alone in its voxel, still isolated.
SeenCloud FilterCloud(const Observation& observation, const CompletionOptions& options) {
  const std::vector<Vec3>& points = observation.points;
  SeenCloud cloud;
  double voxel = options.voxel_size;
  std::vector<int64_t> lone_source;
  if (voxel > 0 && PointsFartherApartThan(observation, voxel * std::sqrt(3.0))) {
    cloud.points = points;  // no cube can hold two points: the filter would return them as they are
    cloud.pixels = observation.pixels;
  } else if (voxel > 0) {
    cloud.points = VoxelDownsample(points, voxel, &lone_source);
    const bool every_point_kept = std::all_of(lone_source.begin(), lone_source.end(), [](int64_t i) { return i >= 0; });
    if (every_point_kept && !observation.pixels.empty()) {
      for (int64_t i : lone_source) cloud.pixels.push_back(observation.pixels[size_t(i)]);
    }
  } else if (options.target_points > 0 && points.size() > options.target_points) {
    cloud.points = EvenlySpread(points, NeighborGrid::MedianSpacing(points), options.target_points);
  } else {
    cloud.points = points;
    cloud.pixels = observation.pixels;
  }
  if (!(options.outlier_std > 0)) return cloud;
  const std::vector<uint32_t> kept = StatisticalInliers(
      cloud.points, *cloud.Neighbors(observation, options.outlier_k + 1), options.outlier_k, options.outlier_std);
  SeenCloud inliers;
  inliers.points.reserve(kept.size());
  for (uint32_t i : kept) inliers.points.push_back(cloud.points[i]);
  if (!cloud.pixels.empty()) {
    inliers.pixels.reserve(kept.size());
    for (uint32_t i : kept) inliers.pixels.push_back(cloud.pixels[i]);
  }
  return inliers;
}

// Normals: the seen points' towards the camera; each mirrored point takes its source's normal reflected.
void OrientedSurfacePoints(const SeenCloud& seen, const Observation& observation,
                           const std::optional<SymmetryPlane>& plane, const CompletionOptions& options,
                           std::vector<Vec3>* points, std::vector<Vec3>* normals) {
  NormalEstimationParams params;
  params.k = options.normal_k;
  params.viewpoint = observation.CameraCentre();
  if (!seen.pixels.empty() && options.image_normal_radius > 0) {
    *normals = EstimateImageNormals(observation, seen.points, seen.pixels, options.image_normal_radius,
                                    seen.median_depth, params.viewpoint);
  } else {
    *normals = EstimateNormals(seen.points, params);
  }
  // Room for the mirror images and a table cap up front: reallocating 100k-point arrays was a millisecond each.
  const size_t n = seen.points.size();
  points->reserve(3 * n);
  normals->reserve(3 * n);
  points->assign(seen.points.begin(), seen.points.end());
  if (!plane) return;
  for (size_t i = 0; i < n; ++i) {
    points->push_back(MirrorPoint(*plane, seen.points[i]));
    normals->push_back(MirrorDirection(*plane, (*normals)[i]));
  }
}

// The underside on a known table: points every `step` (the camera's sampling of the object) over the convex hull of
// the footprint of the seen points and their mirror images (within a step), normals into the table. `step` is at
// least 1/1024 of the footprint's extent.
void AddTableCap(const Vec3& up, double offset, double step, const std::vector<Vec3>& seen,
                 const std::optional<SymmetryPlane>& plane, std::vector<Vec3>* points, std::vector<Vec3>* normals) {
  const Vec3 ax = (std::abs(up.x()) < 0.9 ? Vec3::UnitX() : Vec3::UnitY()).cross(up).normalized();
  const Vec3 ay = up.cross(ax);
  const auto on_table = [&](const Vec3& p) { return cv::Point2f(float(p.dot(ax)), float(p.dot(ay))); };
  std::vector<cv::Point2f> footprint(seen.size()), hull;
  cv::Point2f lo(INFINITY, INFINITY), hi(-INFINITY, -INFINITY);
  for (size_t i = 0; i < seen.size(); ++i) {
    footprint[i] = on_table(seen[i]);
    lo.x = std::min(lo.x, footprint[i].x), lo.y = std::min(lo.y, footprint[i].y);
    hi.x = std::max(hi.x, footprint[i].x), hi.y = std::max(hi.y, footprint[i].y);
  }
  // At most ~1,000 steps across: a focal length out of proportion would ask for billions of cap points.
  step = std::max(step, double(std::max(hi.x - lo.x, hi.y - lo.y)) / 1024);
  // The hull of the extremes per strip `step` wide, across x and across y: within one step of the footprint's hull
  // (a point beaten in its strip lies at most a strip's width outside the hull of those that beat it), and a few
  // hundred points to hull instead of 39k (sorting them all was most of the cap's time).
  std::vector<std::array<int, 4>> extremes;  // per strip: the points of least y and most y in its column, least x
  const auto strip = [&](float value, float origin) { return size_t((value - origin) / float(step)); };
  for (size_t i = 0; i < footprint.size(); ++i) {
    const size_t column = strip(footprint[i].x, lo.x), row = strip(footprint[i].y, lo.y);
    if (std::max(column, row) >= extremes.size()) extremes.resize(std::max(column, row) + 1, {-1, -1, -1, -1});
    const auto better = [&](int* best, bool less, bool along_y) {
      const cv::Point2f& p = footprint[i];
      if (*best < 0) {
        *best = int(i);
        return;
      }
      const cv::Point2f& b = footprint[size_t(*best)];
      const float a = along_y ? p.y : p.x, current = along_y ? b.y : b.x;
      if (less ? a < current : a > current) *best = int(i);
    };
    better(&extremes[column][0], true, true);
    better(&extremes[column][1], false, true);
    better(&extremes[row][2], true, false);
    better(&extremes[row][3], false, false);
  }
  // The mirror plane stands on the table (symmetry_search.h): seen from above, mirroring is a reflection of the
  // footprint, so the mirror images of these extremes bound the mirrored footprint as closely.
  std::vector<cv::Point2f> outline;
  for (const std::array<int, 4>& e : extremes) {
    for (int i : e) {
      if (i < 0) continue;
      outline.push_back(footprint[size_t(i)]);
      if (plane) outline.push_back(on_table(MirrorPoint(*plane, seen[size_t(i)])));
    }
  }
  cv::convexHull(outline, hull, /*clockwise=*/false);
  if (hull.size() < 3) return;
  double lo_x = hull[0].x, hi_x = lo_x, lo_y = hull[0].y, hi_y = lo_y;
  for (const cv::Point2f& h : hull) {
    lo_x = std::min<double>(lo_x, h.x), hi_x = std::max<double>(hi_x, h.x);
    lo_y = std::min<double>(lo_y, h.y), hi_y = std::max<double>(hi_y, h.y);
  }
  // Column by column: the hull (convex) meets the line at x in one interval of y, from the edges that span x.
  for (double x = lo_x + 0.5 * step; x < hi_x; x += step) {
    double y_min = hi_y, y_max = lo_y;
    for (size_t e = 0; e < hull.size(); ++e) {
      const cv::Point2f a = hull[e], b = hull[(e + 1) % hull.size()];
      if ((a.x - x) * (b.x - x) > 0 || a.x == b.x) continue;
      const double y = a.y + (b.y - a.y) * (x - a.x) / (b.x - a.x);
      y_min = std::min(y_min, y), y_max = std::max(y_max, y);
    }
    for (double y = lo_y + 0.5 * step; y < hi_y; y += step) {
      if (y < y_min || y > y_max) continue;
      points->push_back(x * ax + y * ay + offset * up);
      normals->push_back(-up);
    }
  }
}

// The camera's sampling of the object, m: the pixel's footprint at the points' median depth for a depth image kept
// point for point (their nearest neighbours in space are picked by the noise), else the median spacing.
double SamplingStep(const SeenCloud& seen, const Observation& observation) {
  if (seen.pixels.empty()) return NeighborGrid::MedianSpacing(seen.points);
  return seen.median_depth / std::max(observation.intrinsics.fx, observation.intrinsics.fy);
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
  SeenCloud filtered = FilterCloud(observation, options);
  if (!filtered.pixels.empty()) filtered.median_depth = MedianDepth(observation, filtered.pixels);
  const std::vector<Vec3>& seen = filtered.points;
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
  // The search's statistics (the centroid and axes of the footprint, the points it scores) are of the surface, not
  // of the pixels: a depth camera samples a face turned to it several times as densely as a grazing one, and a
  // cloud kept point for point pulled the plane toward the faces the camera looks at (issue 22: the reverse
  // deviation 3.65 → 3.20 mm at 39k points, with Poisson's equal cells). Above target_points it searches the cloud
  // spread evenly.
  const bool spread_evenly = options.target_points > 0 && seen.size() > options.target_points;
  const double step = spread_evenly || options.table_offset ? SamplingStep(filtered, observation) : 0;
  result.plane = SymmetrySearch(observation)
                     .Find(spread_evenly ? EvenlySpread(seen, step, options.target_points) : seen, options.symmetry);
  result.ms.symmetry_ms = MsSince(t);

  if (!report("normals", 0.4)) return std::nullopt;
  t = Clock::now();
  std::vector<Vec3> points, normals;
  OrientedSurfacePoints(filtered, observation, result.plane, options, &points, &normals);
  if (options.table_offset) {
    AddTableCap(options.symmetry.table_normal.normalized(), *options.table_offset, step, seen, result.plane, &points,
                &normals);
  }
  result.surface_points = points.size();
  result.ms.normals_ms = MsSince(t);

  if (!report("surface", 0.55)) return std::nullopt;
  t = Clock::now();
  std::optional<SeenFreeSpace> free_space;
  KnownOutside known_outside;
  if (options.clear_seen_free_space) {
    free_space.emplace(observation, options.free_space_margin_px, options.free_space_depth_margin);
    known_outside = [&free_space](const Vec3& p) { return free_space->Contains(p); };
  }
  PoissonResult surface = ReconstructSurface(points, normals, options.poisson, known_outside);
  result.mesh = std::move(surface.mesh);
  result.poisson = surface.stats;
  result.ms.surface_ms = MsSince(t);
  result.ms.total_ms = MsSince(start);
  return result;
}

}  // namespace graspsim
