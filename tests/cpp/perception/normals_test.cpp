// Plane-fit normals (perception/normals.h) and the k-nearest-neighbour grid under them (neighbor_grid.h).
#include <algorithm>
#include <cmath>
#include <iostream>
#include <random>
#include <utility>

#include <gtest/gtest.h>

#include "core/error.h"
#include "perception/cloud_filters.h"
#include "perception/image_neighbors.h"
#include "perception/neighbor_grid.h"
#include "perception/normals.h"
#include "perception/render_view.h"
#include "perception/shapes.h"
#include "test_util.h"

namespace graspsim {
namespace {

double AngleDeg(const Vec3& a, const Vec3& b) {
  return std::acos(std::clamp(a.normalized().dot(b.normalized()), -1.0, 1.0)) * 180 / M_PI;
}

// A 10 × 10 cm plane z = 0, 2 mm grid, Gaussian noise σ along z, tilted by `rotation`.
std::vector<Vec3> NoisyPlane(double sigma, const Mat3& rotation, uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> noise(0.0, sigma);
  std::vector<Vec3> points;
  for (int i = 0; i < 50; ++i) {
    for (int j = 0; j < 50; ++j) points.push_back(rotation * Vec3(0.002 * i, 0.002 * j, noise(rng)));
  }
  return points;
}

TEST(NeighborGridTest, MatchesBruteForce) {
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> u(-0.05, 0.05);
  std::vector<Vec3> points;
  for (int i = 0; i < 3000; ++i) points.emplace_back(u(rng), u(rng), 0.2 * u(rng));
  points.push_back(points[10]);  // a duplicate: ties go to the lower index
  for (double cell : {NeighborGrid::SuggestCellSize(points, 10), 0.001, 0.2}) {
    const NeighborGrid grid(points, cell);
    std::vector<uint32_t> found;
    for (int q = 0; q < 200; ++q) {
      const Vec3 query = q < 100 ? points[q * 7] : Vec3(u(rng), u(rng), u(rng)) * 1.5;  // some outside the cloud
      grid.Nearest(query, 12, &found);
      std::vector<std::pair<double, uint32_t>> all;
      for (uint32_t i = 0; i < points.size(); ++i) all.emplace_back((points[i] - query).squaredNorm(), i);
      std::sort(all.begin(), all.end());
      ASSERT_EQ(found.size(), 12u);
      for (int k = 0; k < 12; ++k) ASSERT_EQ(found[k], all[k].second) << "cell " << cell << ", query " << q;
    }
  }
}

// A 1280 × 1024, f = 1200 px view of an upright cylinder (r 35 mm, 0.6 m away, 34° up), 1 mm depth noise: ~38k
// points, the pixel spacing (~0.5 mm) below the noise, as in issue 22's full-resolution views. `flying` of the
// object's pixels are thrown 2–10 cm along their rays.
struct CylinderView {
  Vec3 axis_point{0, 0, 0};
  Observation observation;
  std::vector<uint8_t> flying;  // per point
};

CylinderView RenderCylinderView(double flying) {
  CameraIntrinsics k;
  k.width = 1280, k.height = 1024, k.fx = k.fy = 1200, k.cx = 639.5, k.cy = 511.5;
  const Pose camera = test_render::LookAt(Vec3(0.6 * std::cos(0.6), 0, 0.6 * std::sin(0.6)), Vec3(0, 0, 0.05));
  std::mt19937_64 rng(7);
  std::normal_distribution<double> noise(0, 0.001);
  std::uniform_real_distribution<double> u01(0, 1);
  std::vector<uint8_t> thrown(size_t(k.width) * k.height, 0);
  PartialView view;
  view.camera_pose = camera;
  view.image = test_render::Render(test_render::Cylinder(0.035, 0.11, Vec3(0, 0, 0.055)), camera, k, [&](int u, int v) {
    if (u01(rng) >= flying) return noise(rng);
    thrown[size_t(v) * k.width + u] = 1;
    return 0.02 + 0.08 * u01(rng);
  });
  CylinderView out;
  out.observation = Observe(view, 1u << 22);
  for (uint32_t pixel : out.observation.pixels) out.flying.push_back(thrown[pixel]);
  return out;
}

// The window search returns the k nearest of the window's points, in NeighborGrid's order (ties to the lower
// index): checked against sorting the window by hand.
TEST(ImageNeighborsTest, TheKNearestOfTheWindowInTheGridsOrder) {
  const CylinderView view = RenderCylinderView(0);
  const Observation& obs = view.observation;
  const int width = obs.intrinsics.width;
  std::vector<int32_t> at(obs.depth.size(), -1);
  for (size_t i = 0; i < obs.pixels.size(); ++i) at[obs.pixels[i]] = int32_t(i);
  for (int radius : {1, 2}) {
    const ImageNeighbors neighbors(obs.intrinsics, obs.points, obs.pixels, radius);
    std::vector<uint32_t> found;
    for (uint32_t i = 0; i < obs.points.size(); i += 97) {
      const int u0 = int(obs.pixels[i] % width), v0 = int(obs.pixels[i] / width);
      std::vector<std::pair<double, uint32_t>> window;
      for (int v = v0 - radius; v <= v0 + radius; ++v) {
        for (int u = u0 - radius; u <= u0 + radius; ++u) {
          const int32_t j = at[size_t(v) * width + u];
          if (j >= 0) window.emplace_back((obs.points[j] - obs.points[i]).squaredNorm(), uint32_t(j));
        }
      }
      std::sort(window.begin(), window.end());
      neighbors.NearestTo(i, 9, &found);
      ASSERT_EQ(found.size(), std::min<size_t>(9, window.size()));
      for (size_t j = 0; j < found.size(); ++j) ASSERT_EQ(found[j], window[j].second) << "point " << i;
    }
  }
  EXPECT_EQ(ImageNeighbors::RadiusFor(9), 1);
  EXPECT_EQ(ImageNeighbors::RadiusFor(10), 2);
}

// A voxel filter whose cubes no two pixels' points can share (observation.h's bound) keeps every point: checked by
// running the filter at sizes from far below the bound to beyond it.
TEST(ImageNeighborsTest, CubesBelowTheRayBoundHoldOnePointEach) {
  const CylinderView view = RenderCylinderView(0);
  const Observation& obs = view.observation;
  int below = 0;
  for (double voxel : {1e-5, 3e-5, 1e-4, 3e-4, 1e-3}) {
    const bool bound = PointsFartherApartThan(obs, voxel * std::sqrt(3.0));
    if (!bound) continue;
    ++below;
    std::vector<int64_t> lone;
    const std::vector<Vec3> kept = VoxelDownsample(obs.points, voxel, &lone);
    ASSERT_EQ(kept.size(), obs.points.size()) << "voxel " << voxel;
    for (size_t i = 0; i < kept.size(); ++i) ASSERT_EQ(lone[i], int64_t(i));
  }
  EXPECT_GE(below, 2);                                     // 10 and 30 µm at ~0.5 mm per pixel
  EXPECT_FALSE(PointsFartherApartThan(obs, 1e-3 * std::sqrt(3.0)));  // 1 mm cubes: two pixels' points can share
  Observation unorganized = obs;
  unorganized.pixels.clear();
  EXPECT_FALSE(PointsFartherApartThan(unorganized, 1e-5));
}

// The outlier test through the image (3 × 3 windows) on the same view with 2 % of its pixels thrown 2–10 cm along
// their rays: it must find the thrown points and keep the surface. Measured when set: 98.6 % of the thrown points
// removed, 99.9 % of the others kept (the grid's exact k nearest: 100 / 99.98 %).
TEST(ImageNeighborsTest, TheOutlierTestThroughTheImageFindsFlyingPixels) {
  const CylinderView view = RenderCylinderView(0.02);
  const Observation& obs = view.observation;
  const auto rates = [&](const std::vector<uint32_t>& kept) {
    std::vector<uint8_t> is_kept(obs.points.size(), 0);
    for (uint32_t i : kept) is_kept[i] = 1;
    double flying = 0, flying_removed = 0, surface = 0, surface_kept = 0;
    for (size_t i = 0; i < obs.points.size(); ++i) {
      (view.flying[i] ? flying : surface) += 1;
      if (view.flying[i] && !is_kept[i]) flying_removed += 1;
      if (!view.flying[i] && is_kept[i]) surface_kept += 1;
    }
    return std::pair{flying_removed / flying, surface_kept / surface};
  };
  const auto [image_removed, image_kept] =
      rates(StatisticalInliers(obs.points, ImageNeighbors(obs.intrinsics, obs.points, obs.pixels, 1), 8, 2));
  const auto [grid_removed, grid_kept] = rates(
      StatisticalInliers(obs.points, NeighborGrid(obs.points, NeighborGrid::SuggestCellSize(obs.points, 9)), 8, 2));
  std::cout << "thrown removed / surface kept: image " << image_removed << " / " << image_kept << ", grid "
            << grid_removed << " / " << grid_kept << "\n";
  EXPECT_GT(image_removed, 0.95);
  EXPECT_GT(image_kept, 0.95);
}

// The outlier test's figure for every point at once (each pair of a 3 × 3 window measured once for both) is the
// per-point figure, on the view with thrown pixels; other windows and k take the per-point path.
TEST(ImageNeighborsTest, MeanDistancesForAllPointsAreThePerPointOnes) {
  const CylinderView view = RenderCylinderView(0.02);
  const Observation& obs = view.observation;
  for (const auto& [radius, k] : {std::pair{1, 8}, {1, 20}, {1, 5}, {2, 8}}) {
    const ImageNeighbors neighbors(obs.intrinsics, obs.points, obs.pixels, radius);
    const std::vector<double> all = neighbors.MeanDistancesToNearest(obs.points.size(), k);
    ASSERT_EQ(all.size(), obs.points.size());
    for (size_t i = 0; i < obs.points.size(); ++i) {
      ASSERT_NEAR(all[i], neighbors.MeanDistanceToNearest(uint32_t(i), k), 1e-15)
          << "radius " << radius << ", k " << k << ", point " << i;
    }
  }
}

// Normals of a depth image against the cylinder's true (radial) normals. Over a pixel window of 4 mm radius the
// plane fit averages ~290 points spread evenly over the patch; the k = 10 nearest in space sit in a ~1.5 mm ball
// of noise as thick as it is wide. Measured when set: mean 3.1° (window; one-sided windows at the silhouette) against
// 39° (k = 10 in space).
TEST(ImageNormalsTest, WindowPlaneFitsBeatTheNearestInSpaceUnderDepthNoise) {
  const CylinderView view = RenderCylinderView(0);
  const Observation& obs = view.observation;
  const auto mean_error_deg = [&](const std::vector<Vec3>& normals) {
    double sum = 0;
    int count = 0;
    for (size_t i = 0; i < normals.size(); ++i) {
      const Vec3& p = obs.points[i];
      if (p.z() < 0.01 || p.z() > 0.1) continue;  // the side wall, away from the rim
      sum += AngleDeg(normals[i], Vec3(p.x(), p.y(), 0));
      ++count;
    }
    return sum / count;
  };
  const std::vector<Vec3> window =
      EstimateImageNormals(obs, obs.points, obs.pixels, 0.004, MedianDepth(obs, obs.pixels), obs.CameraCentre());
  NormalEstimationParams params;
  params.viewpoint = obs.CameraCentre();
  const std::vector<Vec3> in_space = EstimateNormals(obs.points, params);
  const double window_deg = mean_error_deg(window), space_deg = mean_error_deg(in_space);
  std::cout << "mean normal error: window " << window_deg << " deg, k = 10 in space " << space_deg << " deg\n";
  EXPECT_LT(window_deg, 4.0);
  EXPECT_LT(window_deg, space_deg / 5);
  for (size_t i = 0; i < window.size(); ++i) {
    ASSERT_NEAR(window[i].norm(), 1.0, 1e-12);
    ASSERT_GE(window[i].dot(obs.CameraCentre() - obs.points[i]), 0.0);
  }
}

// The plane fit's tilt error is about σ / (√k · ρ), ρ the RMS distance of the neighbours from their mean (≈ 2.4 mm
// for k = 10 on a 2 mm grid): 0.2 mm noise gives ≈ 1.5° per axis. Bounds: mean < 3°, 99th percentile < 8°.
TEST(NormalsTest, NoisyPlaneWithinStatedAngle) {
  const Mat3 tilt = (Eigen::AngleAxisd(0.4, Vec3(1, 2, 0).normalized())).toRotationMatrix();
  const std::vector<Vec3> points = NoisyPlane(0.0002, tilt, 11);
  NormalEstimationParams params;
  params.viewpoint = tilt * Vec3(0.05, 0.05, 0.5);
  const std::vector<Vec3> normals = EstimateNormals(points, params);
  std::vector<double> angles;
  for (const Vec3& n : normals) {
    EXPECT_NEAR(n.norm(), 1.0, 1e-9);
    angles.push_back(AngleDeg(n, tilt * Vec3::UnitZ()));
  }
  std::sort(angles.begin(), angles.end());
  double mean = 0;
  for (double a : angles) mean += a;
  mean /= double(angles.size());
  const double p99 = angles[angles.size() * 99 / 100];
  std::cout << "noisy plane: mean " << mean << " deg, p99 " << p99 << " deg\n";
  EXPECT_LT(mean, 3.0);
  EXPECT_LT(p99, 8.0);
}

TEST(NormalsTest, NoiselessPlaneIsExact) {
  const std::vector<Vec3> points = NoisyPlane(0.0, Mat3::Identity(), 1);
  NormalEstimationParams params;
  params.viewpoint = Vec3(0, 0, 1);
  for (const Vec3& n : EstimateNormals(points, params)) EXPECT_LT(AngleDeg(n, Vec3::UnitZ()), 1e-6);
}

TEST(NormalsTest, OrientedTowardTheViewpoint) {
  const test_shapes::OrientedCloud sphere = test_shapes::Sphere(0.05, 5000);
  NormalEstimationParams params;
  // From outside: every normal facing the camera side of its tangent plane; on a sphere seen from 1 m away the
  // points facing away from the camera still get n · (v − p) ≥ 0, which flips them inward there — as the paper
  // does, because a real camera sees only the near side.
  params.viewpoint = Vec3(0, 0, 1);
  const std::vector<Vec3> out = EstimateNormals(sphere.points, params);
  double worst = 0;
  for (size_t i = 0; i < out.size(); ++i) {
    EXPECT_GE(out[i].dot(params.viewpoint - sphere.points[i]), 0.0);
    if (sphere.points[i].z() > 0.01) worst = std::max(worst, AngleDeg(out[i], sphere.normals[i]));
  }
  EXPECT_LT(worst, 2.0);  // the near side: the exact outward normal (curvature over 10 neighbours: < 2°)
  // From the centre: every normal inward.
  params.viewpoint = Vec3::Zero();
  const std::vector<Vec3> in = EstimateNormals(sphere.points, params);
  for (size_t i = 0; i < in.size(); ++i) EXPECT_LT(AngleDeg(in[i], -sphere.normals[i]), 2.0);
}

TEST(NormalsTest, SameInputSameBits) {
  const std::vector<Vec3> points = NoisyPlane(0.0005, Mat3::Identity(), 5);
  NormalEstimationParams params;
  params.viewpoint = Vec3(0, 0, 1);
  EXPECT_EQ(EstimateNormals(points, params), EstimateNormals(points, params));
}

TEST(NormalsTest, BadInputThrowsNamingTheField) {
  using test_util::ExpectError;
  const std::vector<Vec3> points = NoisyPlane(0.0, Mat3::Identity(), 1);
  NormalEstimationParams params;
  ExpectError([&] { EstimateNormals({}, params); }, ErrorCode::kInvalidArgument, {"points", "0"});
  params.k = 2;
  ExpectError([&] { EstimateNormals(points, params); }, ErrorCode::kInvalidArgument, {"k", "2", "3..100"});
  params.k = 10;
  params.viewpoint.x() = INFINITY;
  ExpectError([&] { EstimateNormals(points, params); }, ErrorCode::kInvalidArgument, {"viewpoint"});
  params.viewpoint = Vec3::Zero();
  std::vector<Vec3> bad = points;
  bad[42].z() = NAN;
  ExpectError([&] { EstimateNormals(bad, params); }, ErrorCode::kInvalidArgument, {"points[42]"});
}

}  // namespace
}  // namespace graspsim
