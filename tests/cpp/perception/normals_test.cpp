// Plane-fit normals (perception/normals.h) and the k-nearest-neighbour grid under them (neighbor_grid.h).
#include <algorithm>
#include <cmath>
#include <iostream>
#include <random>

#include <gtest/gtest.h>

#include "core/error.h"
#include "perception/neighbor_grid.h"
#include "perception/normals.h"
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
