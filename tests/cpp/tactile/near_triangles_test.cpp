// The pads' segment–triangle test against analytic answers: where a segment meets a triangle, and that a segment
// through an edge or a vertex that triangles share meets at least one of them (the test is watertight).
#include "tactile/near_triangles.h"

#include <cmath>
#include <random>

#include <gtest/gtest.h>

namespace graspsim {
namespace {

TEST(NearTrianglesTest, SegmentMeetsATiltedTriangleWhereThePlaneIs) {
  // The plane z = 0.002 + 0.1 x − 0.05 y through the triangle: a segment up from (x, y, 0) meets it at that z.
  auto plane = [](double x, double y) { return Vec3(x, y, 0.002 + 0.1 * x - 0.05 * y); };
  const Vec3 a = plane(-0.01, -0.01), b = plane(0.01, -0.01), c = plane(0, 0.01);
  double t = -1;
  ASSERT_TRUE(SegmentAlongZMeetsTriangle(Vec3(0.001, 0.002, 0), a, b, c, 0.004, &t));
  EXPECT_NEAR(t, plane(0.001, 0.002).z(), 1e-15);
  ASSERT_TRUE(SegmentAlongZMeetsTriangle(Vec3(0.001, 0.002, 0), c, b, a, 0.004, &t));  // either winding
  EXPECT_NEAR(t, plane(0.001, 0.002).z(), 1e-15);
  EXPECT_FALSE(SegmentAlongZMeetsTriangle(Vec3(0.001, 0.002, 0), a, b, c, 0.001, &t)) << "too short";
  EXPECT_FALSE(SegmentAlongZMeetsTriangle(Vec3(0.001, 0.002, 0.003), a, b, c, 0.004, &t)) << "starts past it";
  EXPECT_FALSE(SegmentAlongZMeetsTriangle(Vec3(0.009, 0.009, 0), a, b, c, 0.004, &t)) << "beside it";
  // In the triangle's plane (a vertical triangle): nothing.
  EXPECT_FALSE(SegmentAlongZMeetsTriangle(Vec3(0, 0, 0), Vec3(-1, 0, 1), Vec3(1, 0, 1), Vec3(0, 0, 2), 3, &t));
}

TEST(NearTrianglesTest, NoSegmentSlipsThroughSharedEdgesOrVertices) {
  // A 20 × 20 grid of irregular (jittered, tilted) vertices split into triangles; segments up through every
  // vertex and the midpoint of every edge, where a test that is not watertight can miss both neighbours.
  constexpr int n = 20;
  std::mt19937 random(3);
  std::uniform_real_distribution<double> jitter(-0.3, 0.3);
  std::vector<Vec3> v;
  for (int j = 0; j <= n; ++j) {
    for (int i = 0; i <= n; ++i) {
      const double x = (i + (i % n ? jitter(random) : 0)) * 1e-3, y = (j + (j % n ? jitter(random) : 0)) * 1e-3;
      v.emplace_back(x, y, 0.002 + 0.3 * x + 0.2 * y + 1e-4 * jitter(random));
    }
  }
  std::vector<std::array<int, 3>> triangles;
  for (int j = 0; j < n; ++j) {
    for (int i = 0; i < n; ++i) {
      const int k = j * (n + 1) + i;
      triangles.push_back({k, k + 1, k + n + 2});
      triangles.push_back({k, k + n + 2, k + n + 1});
    }
  }
  auto hits = [&](double x, double y) {
    int count = 0;
    double t = 0;
    for (const auto& tri : triangles) count += SegmentAlongZMeetsTriangle(Vec3(x, y, 0), v[tri[0]], v[tri[1]], v[tri[2]], 1, &t);
    return count;
  };
  int probes = 0;
  for (const auto& tri : triangles) {
    for (int e = 0; e < 3; ++e) {
      const Vec3& p = v[tri[e]];
      const Vec3 mid = 0.5 * (v[tri[e]] + v[tri[(e + 1) % 3]]);
      const bool on_border = [&](const Vec3& q) {
        return q.x() <= 1e-12 || q.y() <= 1e-12 || q.x() >= n * 1e-3 - 1e-12 || q.y() >= n * 1e-3 - 1e-12;
      }(mid);
      if (on_border) continue;
      EXPECT_GE(hits(p.x(), p.y()), 1) << "vertex " << p.transpose();
      EXPECT_GE(hits(mid.x(), mid.y()), 1) << "edge midpoint " << mid.transpose();
      probes += 2;
    }
  }
  EXPECT_GT(probes, 2000);
}

}  // namespace
}  // namespace graspsim
