// The collision library's private point queries against hand-computed answers: primitive signed distances,
// Ericson's closest point on a triangle, and the Embree mesh query (parity, closest point, near-surface sign).
#include <cmath>
#include <limits>
#include <numbers>
#include <random>

#include <gtest/gtest.h>

#include "collision/mesh_query.h"
#include "collision/primitive_sdf.h"
#include "collision/samples.h"
#include "collision_fixtures.h"

namespace graspsim::collision {
namespace {

using namespace collision_fixtures;

constexpr double kExact = 1e-12;

TEST(ContactPrimitives, BoxDepthInsideOutsideAndAtACorner) {
  const Vec3 half(0.1, 0.2, 0.3);
  Vec3 n;
  EXPECT_NEAR(BoxDepth(half, Vec3(0.09, 0, 0), &n), 0.01, kExact);
  EXPECT_EQ(n, Vec3::UnitX());
  EXPECT_NEAR(BoxDepth(half, Vec3(0, -0.15, 0.1), &n), 0.05, kExact);
  EXPECT_EQ(n, -Vec3::UnitY());
  EXPECT_NEAR(BoxDepth(half, Vec3(0, 0, 0.4), &n), -0.1, kExact);
  EXPECT_EQ(n, Vec3::UnitZ());
  EXPECT_NEAR(BoxDepth(half, Vec3(0.13, 0.24, 0), &n), -0.05, kExact);  // beyond an edge: a 3-4-5 triangle
  EXPECT_LT((n - Vec3(0.6, 0.8, 0)).norm(), kExact);
}

TEST(ContactPrimitives, SphereAndCylinderDepths) {
  Vec3 n;
  EXPECT_NEAR(SphereDepth(0.5, Vec3(0, 0.3, 0.4), &n), 0, kExact);
  EXPECT_NEAR(SphereDepth(0.5, Vec3(0, 0.06, 0.08), &n), 0.4, kExact);
  EXPECT_LT((n - Vec3(0, 0.6, 0.8)).norm(), kExact);
  // Cylinder r = 0.1, from z = -0.2 to 0.2.
  EXPECT_NEAR(CylinderDepth(0.1, 0.2, Vec3(0.06, 0.08, 0.15), &n), 0, kExact);  // on the side
  EXPECT_NEAR(CylinderDepth(0.1, 0.2, Vec3(0.03, 0.04, 0.0), &n), 0.05, kExact);
  EXPECT_LT((n - Vec3(0.6, 0.8, 0)).norm(), kExact);
  EXPECT_NEAR(CylinderDepth(0.1, 0.2, Vec3(0, 0.01, -0.18), &n), 0.02, kExact);  // nearer the bottom cap
  EXPECT_EQ(n, -Vec3::UnitZ());
  EXPECT_NEAR(CylinderDepth(0.1, 0.2, Vec3(0.13, 0, 0.24), &n), -0.05, kExact);  // beyond the rim
  EXPECT_LT((n - Vec3(0.6, 0, 0.8)).norm(), kExact);
  EXPECT_NEAR(CylinderDepth(0.1, 0.2, Vec3(0, 0.3, 0), &n), -0.2, kExact);
  EXPECT_EQ(n, Vec3::UnitY());
}

TEST(ContactPrimitives, ClosestPointOnTriangleInEveryRegion) {
  const Vec3 a(0, 0, 0), b(1, 0, 0), c(0, 1, 0);
  auto closest = [&](double x, double y, double z) { return ClosestPointOnTriangle(Vec3(x, y, z), a, b, c); };
  EXPECT_LT((closest(0.2, 0.3, 0.5) - Vec3(0.2, 0.3, 0)).norm(), kExact);   // face
  EXPECT_LT((closest(-1, -1, 1) - a).norm(), kExact);                       // vertex a
  EXPECT_LT((closest(2, -0.5, 0) - b).norm(), kExact);                      // vertex b
  EXPECT_LT((closest(-0.5, 2, 0) - c).norm(), kExact);                      // vertex c
  EXPECT_LT((closest(0.5, -1, 0) - Vec3(0.5, 0, 0)).norm(), kExact);        // edge ab
  EXPECT_LT((closest(-1, 0.5, 0) - Vec3(0, 0.5, 0)).norm(), kExact);        // edge ac
  EXPECT_LT((closest(1, 1, 3) - Vec3(0.5, 0.5, 0)).norm(), kExact);         // edge bc
  EXPECT_LT((ClosestPointOnTriangle(Vec3(0, 1, 0), a, b, b) - Vec3(0, 0, 0)).norm(), kExact);  // degenerate
}

TEST(ContactPrimitives, SphereSamplesAreSpacedAsAsked) {
  const double spacing = 0.005, r = 0.05;
  const auto points = SampleGeometry(SphereGeometry(r), spacing);
  // Every point of the sphere is within about one spacing of a sample (Fibonacci sets cover evenly).
  std::mt19937 rng(7);
  std::normal_distribution<double> gauss;
  double worst = 0;
  for (int i = 0; i < 2000; ++i) {
    const Vec3 q = r * Vec3(gauss(rng), gauss(rng), gauss(rng)).normalized();
    double nearest = 1;
    for (const Vec3& p : points) nearest = std::min(nearest, (p - q).norm());
    worst = std::max(worst, nearest);
  }
  EXPECT_LT(worst, spacing);
  for (const Vec3& p : points) EXPECT_NEAR(p.norm(), r, kExact);
}

TEST(ContactMeshQuery, SphereMeshDepthMatchesSphereWithinFacetError) {
  const double r = 0.05;
  const int slices = 64, stacks = 32;
  const double sag = r * (1 - std::cos(std::numbers::pi / stacks));  // facets lie at most this far inside
  const MeshBvh bvh(SphereMesh(r, slices, stacks));
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> coordinate(-1.2 * r, 1.2 * r);
  int inside = 0;
  for (int i = 0; i < 5000; ++i) {
    const Vec3 p(coordinate(rng), coordinate(rng), coordinate(rng));
    Vec3 n_exact, n_mesh;
    const double exact = SphereDepth(r, p, &n_exact);
    double depth = 0;
    const bool hit = bvh.Depth(p, 0.01, &depth, &n_mesh);
    if (exact > 2 * sag) {
      ASSERT_TRUE(hit) << p.transpose();
      EXPECT_NEAR(depth, exact, 2 * sag);
      ++inside;
    } else if (exact < -0.01 - sag) {
      EXPECT_FALSE(hit);
    } else if (hit) {
      EXPECT_NEAR(depth, exact, 2 * sag);
    }
  }
  EXPECT_GT(inside, 1000);
}

// The clearance grid (a cell's lower bound on the distance outside the surface) may only skip work: every answer,
// on a cell's first query and on later ones, equals brute force over all triangles (the mesh is convex, so
// inside means behind every face's plane).
TEST(ContactMeshQuery, ClearanceGridChangesNoAnswer) {
  const double r = 0.05;
  const auto mesh = SphereMesh(r, 16, 8);
  const MeshBvh bvh(mesh);
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> coordinate(-1.1 * r, 1.1 * r);
  std::vector<Vec3> points(20000);
  for (Vec3& p : points) p = Vec3(coordinate(rng), coordinate(rng), coordinate(rng));
  int hits = 0, checked = 0;
  for (int pass = 0; pass < 2; ++pass) {
    for (const Vec3& p : points) {
      double distance = std::numeric_limits<double>::infinity(), behind = -distance;
      for (const auto& t : mesh->triangles) {
        const Vec3 a = mesh->vertices[t[0]].cast<double>(), b = mesh->vertices[t[1]].cast<double>(),
                   c = mesh->vertices[t[2]].cast<double>();
        const Vec3 normal = (b - a).cross(c - a);
        if (normal.norm() == 0) continue;
        distance = std::min(distance, (p - ClosestPointOnTriangle(p, a, b, c)).norm());
        behind = std::max(behind, normal.normalized().dot(p - a));
      }
      if (distance < 1e-9) continue;  // on the surface, float noise decides the side
      const bool inside = behind < 0;
      for (const double margin : {0.0, 5e-4, 3e-3}) {
        double depth = 0;
        Vec3 n;
        const bool hit = bvh.Depth(p, margin, &depth, &n);
        ++checked;
        ASSERT_EQ(hit, inside || distance < margin) << p.transpose() << " margin " << margin << " pass " << pass;
        if (hit) {
          ++hits;
          EXPECT_NEAR(depth, inside ? distance : -distance, 1e-12);
        }
      }
    }
  }
  EXPECT_GT(hits, checked / 4);
}

TEST(ContactMeshQuery, TwoCubesInOneMeshCountCrossingsNotHits) {
  // Two disjoint unit cubes in one mesh: a ray from inside the first also crosses the second twice.
  TriangleMesh mesh = *BoxMesh(Vec3(1, 1, 1));
  const size_t offset = mesh.vertices.size();
  for (size_t i = 0; i < offset; ++i) mesh.vertices.push_back(mesh.vertices[i] + Eigen::Vector3f(2, 4, 6));
  for (size_t i = 0; i < 12; ++i) {
    auto t = mesh.triangles[i];
    for (auto& v : t) v += static_cast<uint32_t>(offset);
    mesh.triangles.push_back(t);
  }
  const MeshBvh bvh(std::make_shared<const TriangleMesh>(std::move(mesh)));
  double depth = 0;
  Vec3 n;
  ASSERT_TRUE(bvh.Depth(Vec3(0.1, 0.1, 0.1), 0, &depth, &n));
  EXPECT_NEAR(depth, 0.4, 1e-7);
  ASSERT_TRUE(bvh.Depth(Vec3(2.3, 4, 6), 0, &depth, &n));
  EXPECT_NEAR(depth, 0.2, 1e-7);
  EXPECT_EQ(n, Vec3::UnitX());
  EXPECT_FALSE(bvh.Depth(Vec3(1, 2, 3), 0, &depth, &n));  // between them
  EXPECT_FALSE(bvh.Depth(Vec3(1, 2, 3), 0.5, &depth, &n));
  ASSERT_TRUE(bvh.Depth(Vec3(0.7, 0, 0), 0.5, &depth, &n));  // 0.2 outside, within the margin
  EXPECT_NEAR(depth, -0.2, 1e-7);
  EXPECT_EQ(n, Vec3::UnitX());
}

TEST(ContactMeshQuery, PointsOnTheSurfaceAreNotInside) {
  const auto mesh = BoxMesh(Vec3(1, 1, 1));
  const MeshBvh bvh(mesh);
  double depth = 0;
  Vec3 n;
  // Vertices, edge midpoints and face centres: never a contact with positive depth.
  for (const Vec3& p : {Vec3(0.5, 0.5, 0.5), Vec3(0.5, 0, 0.5), Vec3(0, 0, -0.5), Vec3(-0.5, 0.25, 0.1)}) {
    if (bvh.Depth(p, 0, &depth, &n)) {
      EXPECT_LE(depth, 1e-7) << p.transpose();
    }
  }
  // Within float noise of a face (both round to z = 0.5 as the ray's origin), the face normal decides: just
  // outside is never a contact; just inside is one of that depth, or (parity said outside) none.
  EXPECT_FALSE(bvh.Depth(Vec3(0.1, 0.2, 0.5 + 1e-8), 0, &depth, &n));
  if (bvh.Depth(Vec3(0.1, 0.2, 0.5 - 1e-8), 0, &depth, &n)) {
    EXPECT_NEAR(depth, 1e-8, 1e-9);
    EXPECT_EQ(n, Vec3::UnitZ());
  }
}

}  // namespace
}  // namespace graspsim::collision
