// Marching cubes (perception/marching_cubes.h): the derived case table gives closed, consistently oriented
// surfaces for every sign pattern, and the right geometry on an analytic field.
#include <cmath>
#include <random>

#include <gtest/gtest.h>

#include "perception/marching_cubes.h"
#include "perception/mesh_metrics.h"

namespace graspsim {
namespace {

// Random values inside, a border of "outside" values: every one of the 256 corner patterns shows up many times,
// ambiguous faces included, and the result must still be a closed, oriented surface.
TEST(MarchingCubesTest, RandomFieldsGiveClosedOrientedSurfaces) {
  const int n = 24;
  std::mt19937_64 rng(9);
  std::uniform_real_distribution<float> u(-1, 1);
  for (int trial = 0; trial < 5; ++trial) {
    std::vector<float> values(n * n * n);
    for (int k = 0; k < n; ++k) {
      for (int j = 0; j < n; ++j) {
        for (int i = 0; i < n; ++i) {
          const bool border = i == 0 || j == 0 || k == 0 || i == n - 1 || j == n - 1 || k == n - 1;
          values[(k * n + j) * n + i] = border ? 1.0f : u(rng);
        }
      }
    }
    GridSamples grid;
    grid.nodes = Eigen::Vector3i::Constant(n);
    grid.values = values.data();
    const TriangleMesh mesh = ExtractIsoSurface(grid, 0.0f);
    const EdgeCounts edges = CountEdges(mesh);
    EXPECT_TRUE(edges.Closed()) << "boundary " << edges.boundary << ", non-manifold " << edges.non_manifold
                                << ", misoriented " << edges.misoriented;
    EXPECT_GT(EnclosedVolume(mesh), 0.0);  // the inside (< iso) is enclosed: triangles face outward
  }
}

// f = |x| − R sampled on a grid: the iso-surface 0 is the sphere of radius R within the interpolation error.
TEST(MarchingCubesTest, SphereFieldGivesSphere) {
  const int n = 41;
  const double spacing = 0.01, R = 0.13;
  std::vector<float> values(n * n * n);
  const Vec3 origin = Vec3::Constant(-0.2);
  for (int k = 0; k < n; ++k) {
    for (int j = 0; j < n; ++j) {
      for (int i = 0; i < n; ++i) values[(k * n + j) * n + i] = float((origin + spacing * Vec3(i, j, k)).norm() - R);
    }
  }
  GridSamples grid{Eigen::Vector3i::Constant(n), origin, spacing, values.data()};
  const TriangleMesh mesh = ExtractIsoSurface(grid, 0.0f);
  EXPECT_TRUE(CountEdges(mesh).Closed());
  for (const auto& v : mesh.vertices) EXPECT_NEAR(v.cast<double>().norm(), R, 0.05 * spacing);
  // Inscribed polyhedron: a little under the sphere's volume.
  const double exact = 4.0 / 3 * M_PI * R * R * R;
  EXPECT_NEAR(EnclosedVolume(mesh) / exact, 1.0, 0.02);
  EXPECT_LT(EnclosedVolume(mesh), exact);
}

}  // namespace
}  // namespace graspsim
