// Message → engine conversion: the boundary checks of every request field.
#include "rpc/convert.h"

#include <cmath>
#include <cstring>

#include <gtest/gtest.h>

#include "test_util.h"

namespace graspsim::rpc {
namespace {

using test_util::ExpectError;

v1::MeshData PackedMesh(const std::vector<float>& vertices, const std::vector<uint32_t>& triangles) {
  v1::MeshData mesh;
  mesh.set_vertices(vertices.data(), vertices.size() * sizeof(float));
  mesh.set_triangles(triangles.data(), triangles.size() * sizeof(uint32_t));
  return mesh;
}

TEST(ConvertPose, AbsentOrientationIsIdentityAndNearUnitIsNormalised) {
  v1::Pose pose;
  pose.mutable_position()->set_z(0.75);
  Pose out = PoseFromProto("pose", pose);
  EXPECT_EQ(out.position, Vec3(0, 0, 0.75));
  EXPECT_EQ(out.orientation.coeffs(), Quat::Identity().coeffs());
  pose.mutable_orientation()->set_w(0.0);
  pose.mutable_orientation()->set_z(1.0004);
  out = PoseFromProto("pose", pose);
  EXPECT_NEAR(out.orientation.z(), 1.0, 1e-15);
}

TEST(ConvertPose, BadValuesNameTheField) {
  v1::Pose pose;
  pose.mutable_orientation();  // present and all zero
  ExpectError([&] { PoseFromProto("poses[3].pose", pose); }, ErrorCode::kInvalidArgument,
              {"poses[3].pose.orientation", "norm 0"});
  pose.mutable_orientation()->set_w(1);
  pose.mutable_position()->set_y(INFINITY);
  ExpectError([&] { PoseFromProto("pose", pose); }, ErrorCode::kInvalidArgument, {"pose.position", "inf"});
}

TEST(ConvertInertial, MassAndTensorChecked) {
  v1::Inertial inertial;
  inertial.set_mass(0.1);
  inertial.set_ixx(1e-4);
  inertial.set_iyy(1e-4);
  inertial.set_izz(1e-4);
  EXPECT_DOUBLE_EQ(InertialFromProto("inertial", inertial).inertia(2, 2), 1e-4);
  inertial.set_ixy(2e-4);  // |ixy| > ixx: indefinite
  ExpectError([&] { InertialFromProto("inertial", inertial); }, ErrorCode::kInvalidArgument,
              {"inertial", "positive definite"});
  inertial.set_ixy(0);
  inertial.set_mass(0);
  ExpectError([&] { InertialFromProto("inertial", inertial); }, ErrorCode::kInvalidArgument, {"inertial.mass"});
  inertial.set_mass(-1);
  ExpectError([&] { InertialFromProto("inertial", inertial); }, ErrorCode::kInvalidArgument, {"-1"});
  inertial.set_mass(NAN);
  ExpectError([&] { InertialFromProto("inertial", inertial); }, ErrorCode::kInvalidArgument, {"nan"});
}

TEST(ConvertMesh, PackedArraysRoundTrip) {
  const v1::MeshData mesh = PackedMesh({0, 0, 0, 1, 0, 0, 0, 1, 0}, {0, 1, 2});
  Limits limits;
  const TriangleMesh decoded = MeshFromProto("geometry.mesh", mesh, limits);
  ASSERT_EQ(decoded.vertices.size(), 3u);
  EXPECT_EQ(decoded.vertices[1], Eigen::Vector3f(1, 0, 0));
  v1::MeshData encoded;
  ToProto(decoded, &encoded);
  EXPECT_EQ(encoded.SerializeAsString(), mesh.SerializeAsString());
}

TEST(ConvertMesh, EveryMalformedMeshIsRejected) {
  Limits limits;
  ExpectError([&] { MeshFromProto("geometry.mesh", PackedMesh({0, 0, 0, 1}, {}), limits); },
              ErrorCode::kInvalidArgument, {"geometry.mesh.vertices", "16 bytes"});
  v1::MeshData odd = PackedMesh({0, 0, 0, 1, 0, 0, 0, 1, 0}, {0, 1, 2});
  odd.mutable_triangles()->push_back('\0');
  ExpectError([&] { MeshFromProto("geometry.mesh", odd, limits); }, ErrorCode::kInvalidArgument,
              {"geometry.mesh.triangles"});
  ExpectError([&] { MeshFromProto("geometry.mesh", PackedMesh({0, 0, 0, 1, 0, 0, 0, 1, 0}, {0, 1, 7}), limits); },
              ErrorCode::kInvalidArgument, {"index 7"});
  ExpectError([&] { MeshFromProto("geometry.mesh", PackedMesh({}, {}), limits); }, ErrorCode::kInvalidArgument,
              {"empty"});
  limits.max_triangles_per_mesh = 1;
  ExpectError([&] { MeshFromProto("g", PackedMesh({0, 0, 0, 1, 0, 0, 0, 1, 0}, {0, 1, 2, 2, 1, 0}), limits); },
              ErrorCode::kResourceExhausted, {"2 triangles", "limit of 1"});
}

}  // namespace
}  // namespace graspsim::rpc
