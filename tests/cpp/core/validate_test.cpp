// Boundary checks: each rule rejects with kInvalidArgument and names the field and the value.
#include "core/validate.h"

#include <cmath>
#include <limits>

#include <gtest/gtest.h>

#include "core/error.h"
#include "core/mesh.h"
#include "test_util.h"

namespace graspsim {
namespace {

using test_util::ExpectError;

TEST(Validate, FiniteRejectsNanAndInfNamingTheField) {
  ExpectError([] { CheckFinite("pose.position.x", std::nan("")); }, ErrorCode::kInvalidArgument,
              {"pose.position.x", "nan"});
  ExpectError([] { CheckFinite("box.size", Vec3(1, INFINITY, 1)); }, ErrorCode::kInvalidArgument,
              {"box.size", "inf"});
  EXPECT_NO_THROW(CheckFinite("x", 1e300));
}

TEST(Validate, PositiveRejectsZeroNegativeAndNan) {
  ExpectError([] { CheckPositive("inertial.mass", 0.0); }, ErrorCode::kInvalidArgument, {"inertial.mass", "0"});
  ExpectError([] { CheckPositive("inertial.mass", -2.5); }, ErrorCode::kInvalidArgument, {"-2.5"});
  ExpectError([] { CheckPositive("inertial.mass", std::nan("")); }, ErrorCode::kInvalidArgument, {"nan"});
  EXPECT_NO_THROW(CheckPositive("m", 1e-9));
}

TEST(Validate, QuaternionNormalisedWithinToleranceRejectedBeyond) {
  const Quat q = CheckQuaternion("q", Quat(1.0005, 0, 0, 0));
  EXPECT_NEAR(q.norm(), 1.0, 1e-15);
  EXPECT_NEAR(q.w(), 1.0, 1e-15);
  ExpectError([] { CheckQuaternion("pose.orientation", Quat(0, 0, 0, 0)); }, ErrorCode::kInvalidArgument,
              {"pose.orientation", "norm 0"});
  ExpectError([] { CheckQuaternion("pose.orientation", Quat(2, 0, 0, 0)); }, ErrorCode::kInvalidArgument,
              {"norm 2"});
  ExpectError([] { CheckQuaternion("q", Quat(std::nan(""), 0, 0, 0)); }, ErrorCode::kInvalidArgument,
              {"not finite"});
}

TEST(Validate, InertiaMustBeSymmetricPositiveDefiniteAndPhysical) {
  // A 0.1 kg, 5 cm cube: m a^2 / 6 on the diagonal.
  const double i = 0.1 * 0.05 * 0.05 / 6;
  EXPECT_NO_THROW(CheckInertia("inertial", Mat3(Vec3(i, i, i).asDiagonal())));
  ExpectError([] { CheckInertia("inertial", Mat3(Vec3(-1, 1, 1).asDiagonal())); }, ErrorCode::kInvalidArgument,
              {"inertial", "not positive definite"});
  ExpectError([] { CheckInertia("inertial", Mat3(Vec3(3, 1, 1).asDiagonal())); }, ErrorCode::kInvalidArgument,
              {"triangle inequality"});
  Mat3 asymmetric = Mat3::Identity();
  asymmetric(0, 1) = 0.1;
  ExpectError([&] { CheckInertia("inertial", asymmetric); }, ErrorCode::kInvalidArgument, {"not symmetric"});
  // A thin rod is the limit of the triangle inequality (I_x = I_y, I_z -> 0): still accepted.
  EXPECT_NO_THROW(CheckInertia("rod", Mat3(Vec3(1, 1, 1e-9).asDiagonal())));
}

TEST(Validate, NamesAndPaths) {
  EXPECT_NO_THROW(CheckName("name", "cube_5cm-2.v1"));
  ExpectError([] { CheckName("name", ""); }, ErrorCode::kInvalidArgument, {"name"});
  ExpectError([] { CheckName("name", "a/b"); }, ErrorCode::kInvalidArgument, {"'a/b'"});
  ExpectError([] { CheckName("name", std::string(65, 'a')); }, ErrorCode::kInvalidArgument, {"1..64"});
  EXPECT_NO_THROW(CheckRelativePath("path", "meshes/finger.stl"));
  for (const char* bad : {"", "/etc/passwd", "../x", "a/../../b", "a\\b", "..", "a/.."}) {
    ExpectError([&] { CheckRelativePath("header.path", bad); }, ErrorCode::kInvalidArgument, {"header.path"});
  }
}

TEST(Mesh, ValidationRules) {
  TriangleMesh mesh;
  ExpectError([&] { ValidateMesh(mesh, "geometry.mesh", 10); }, ErrorCode::kInvalidArgument, {"empty"});
  mesh.vertices = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  mesh.triangles = {{0, 1, 2}};
  EXPECT_NO_THROW(ValidateMesh(mesh, "m", 1));
  mesh.triangles.push_back({0, 1, 3});
  ExpectError([&] { ValidateMesh(mesh, "geometry.mesh", 10); }, ErrorCode::kInvalidArgument,
              {"geometry.mesh", "triangle 1", "index 3"});
  mesh.triangles.back() = {0, 2, 1};
  ExpectError([&] { ValidateMesh(mesh, "geometry.mesh", 1); }, ErrorCode::kResourceExhausted, {"2 triangles"});
  mesh.vertices[1].x() = std::numeric_limits<float>::quiet_NaN();
  ExpectError([&] { ValidateMesh(mesh, "geometry.mesh", 10); }, ErrorCode::kInvalidArgument, {"vertex 1"});
}

TEST(Mesh, BoundsOfAUnitTriangle) {
  TriangleMesh mesh;
  mesh.vertices = {{-1, 0, 2}, {1, 3, 0}, {0, -2, 1}};
  mesh.triangles = {{0, 1, 2}};
  Eigen::Vector3f min, max;
  MeshBounds(mesh, &min, &max);
  EXPECT_EQ(min, Eigen::Vector3f(-1, -2, 0));
  EXPECT_EQ(max, Eigen::Vector3f(1, 3, 2));
}

}  // namespace
}  // namespace graspsim
