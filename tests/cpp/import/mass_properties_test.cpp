// Mass properties of solid geometry against closed forms: each primitive, a triangle-mesh cube against the box
// formula (also wound inside out), and two parts combined by the parallel-axis theorem against the one solid they
// make.
#include <cmath>

#include <gtest/gtest.h>

#include "import/mass_properties.h"

namespace graspsim {
namespace {

constexpr double kTolerance = 1e-12;

Geometry Box(const Vec3& size, const Pose& origin = {}) {
  Geometry g;
  g.kind = Geometry::Kind::kBox;
  g.box_size = size;
  g.origin = origin;
  return g;
}

// A cube of edge `a` centred on the origin as 12 counter-clockwise triangles (or clockwise when inside_out).
Geometry MeshCube(double a, bool inside_out) {
  auto mesh = std::make_shared<TriangleMesh>();
  for (int i = 0; i < 8; ++i) {
    mesh->vertices.emplace_back((i & 1 ? 0.5f : -0.5f) * a, (i & 2 ? 0.5f : -0.5f) * a, (i & 4 ? 0.5f : -0.5f) * a);
  }
  const uint32_t faces[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
  for (const auto& f : faces) {
    mesh->triangles.push_back({f[0], f[1], f[2]});
    mesh->triangles.push_back({f[0], f[2], f[3]});
  }
  if (inside_out) {
    for (auto& t : mesh->triangles) std::swap(t[1], t[2]);
  }
  Geometry g;
  g.kind = Geometry::Kind::kMesh;
  g.mesh = mesh;
  return g;
}

TEST(MassPropertiesTest, PrimitivesMatchTheirClosedForms) {
  const Inertial box = SolidMassProperties({Box(Vec3(0.1, 0.2, 0.3))}, 1000);
  EXPECT_NEAR(box.mass, 6.0, kTolerance);
  EXPECT_NEAR(box.inertia(0, 0), 6.0 / 12 * (0.04 + 0.09), kTolerance);
  EXPECT_NEAR(box.inertia(2, 2), 6.0 / 12 * (0.01 + 0.04), kTolerance);

  Geometry sphere;
  sphere.kind = Geometry::Kind::kSphere;
  sphere.radius = 0.05;
  const Inertial ball = SolidMassProperties({sphere}, 7800);
  const double m = 7800 * 4.0 / 3.0 * M_PI * 1.25e-4;
  EXPECT_NEAR(ball.mass, m, 1e-12 * m);
  EXPECT_NEAR(ball.inertia(1, 1), 0.4 * m * 0.0025, kTolerance);

  Geometry cylinder;
  cylinder.kind = Geometry::Kind::kCylinder;
  cylinder.radius = 0.1;
  cylinder.length = 0.4;
  const Inertial can = SolidMassProperties({cylinder}, 500);
  const double mc = 500 * M_PI * 0.01 * 0.4;
  EXPECT_NEAR(can.mass, mc, 1e-12 * mc);
  EXPECT_NEAR(can.inertia(2, 2), mc * 0.01 / 2, kTolerance);
  EXPECT_NEAR(can.inertia(0, 0), mc * (3 * 0.01 + 0.16) / 12, kTolerance);
}

TEST(MassPropertiesTest, MeshCubeEqualsTheBoxEvenInsideOut) {
  const Inertial box = SolidMassProperties({Box(Vec3::Constant(0.2))}, 1000);
  for (bool inside_out : {false, true}) {
    const Inertial mesh = SolidMassProperties({MeshCube(0.2, inside_out)}, 1000);
    EXPECT_NEAR(mesh.mass, box.mass, 1e-6 * box.mass);  // float32 vertices
    EXPECT_LT(mesh.center_of_mass.norm(), 1e-9);
    EXPECT_LT((mesh.inertia - box.inertia).cwiseAbs().maxCoeff(), 1e-6 * box.inertia(0, 0));
  }
}

TEST(MassPropertiesTest, PartsCombineByTheParallelAxisTheorem) {
  // Two 0.1 m cubes side by side along x, turned about z by 90° as a pair: one 0.2 × 0.1 × 0.1 box along y.
  const Quat yaw(Eigen::AngleAxisd(M_PI / 2, Vec3::UnitZ()));
  const Vec3 shift(0.3, -0.1, 0.05);
  const Inertial pair = SolidMassProperties(
      {Box(Vec3::Constant(0.1), {shift + yaw * Vec3(-0.05, 0, 0), yaw}), Box(Vec3::Constant(0.1), {shift + yaw * Vec3(0.05, 0, 0), yaw})},
      1000);
  const Inertial one = SolidMassProperties({Box(Vec3(0.1, 0.2, 0.1), {shift, Quat::Identity()})}, 1000);
  EXPECT_NEAR(pair.mass, one.mass, kTolerance);
  EXPECT_LT((pair.center_of_mass - shift).norm(), kTolerance);
  EXPECT_LT((pair.inertia - one.inertia).cwiseAbs().maxCoeff(), kTolerance);
}

TEST(MassPropertiesTest, NothingWithoutVolume) {
  Geometry flat = MeshCube(0.1, false);
  auto mesh = std::make_shared<TriangleMesh>(*flat.mesh);
  mesh->triangles.resize(2);  // one face, seen from both sides: a sheet that encloses nothing
  mesh->triangles.push_back({mesh->triangles[0][0], mesh->triangles[0][2], mesh->triangles[0][1]});
  mesh->triangles.push_back({mesh->triangles[1][0], mesh->triangles[1][2], mesh->triangles[1][1]});
  flat.mesh = mesh;
  EXPECT_EQ(SolidMassProperties({flat}, 1000).mass, 0);
  EXPECT_EQ(SolidMassProperties({}, 1000).mass, 0);
}

}  // namespace
}  // namespace graspsim
