// Message → engine conversion: the boundary checks of every request field.
#include "rpc/convert.h"

#include <cmath>
#include <cstring>

#include <gtest/gtest.h>

#include "test_util.h"

namespace graspsim::rpc {
namespace {

using test_util::ExpectError;

const std::string* NoFile(const std::string&) { return nullptr; }

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

TEST(ConvertMaterial, StaticBelowDynamicRejected) {
  v1::Material material;
  material.set_static_friction(0.3);
  material.set_dynamic_friction(0.5);
  ExpectError([&] { MaterialFromProto("material", material, Material()); }, ErrorCode::kInvalidArgument,
              {"static_friction", "dynamic_friction"});
  material.set_dynamic_friction(-0.1);
  ExpectError([&] { MaterialFromProto("material", material, Material()); }, ErrorCode::kInvalidArgument,
              {"material.dynamic_friction"});
}

TEST(ConvertMaterial, UnsetFieldsKeepTheBodysOwn) {
  v1::Material material;
  material.set_contact_stiffness(2e4);  // contact fields only: friction stays the base's
  Material base;
  base.static_friction = 0.9;
  base.dynamic_friction = 0.7;
  Material out = MaterialFromProto("material", material, base);
  EXPECT_EQ(out.static_friction, 0.9);
  EXPECT_EQ(out.dynamic_friction, 0.7);
  EXPECT_EQ(out.contact_stiffness, 2e4);
  material.set_static_friction(0);  // explicitly frictionless
  material.set_dynamic_friction(0);
  out = MaterialFromProto("material", material, base);
  EXPECT_EQ(out.static_friction, 0);
  EXPECT_EQ(out.dynamic_friction, 0);
  material.clear_dynamic_friction();  // 0.5 against the base's 0.7 dynamic: refused, naming both
  material.set_static_friction(0.5);
  ExpectError([&] { MaterialFromProto("material", material, base); }, ErrorCode::kInvalidArgument,
              {"static_friction 0.5", "dynamic_friction 0.7"});
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

TEST(ConvertGeometry, PrimitivesMustBePositiveAndFilesUploaded) {
  Limits limits;
  v1::Geometry geometry;
  ExpectError([&] { GeometryFromProto("geometry", geometry, NoFile, limits); }, ErrorCode::kInvalidArgument,
              {"no shape"});
  geometry.mutable_box()->mutable_size()->set_x(0.1);
  geometry.mutable_box()->mutable_size()->set_y(0.1);
  ExpectError([&] { GeometryFromProto("geometry", geometry, NoFile, limits); }, ErrorCode::kInvalidArgument,
              {"geometry.box.size.z"});
  geometry.mutable_sphere()->set_radius(NAN);
  ExpectError([&] { GeometryFromProto("geometry", geometry, NoFile, limits); }, ErrorCode::kInvalidArgument,
              {"geometry.sphere.radius", "nan"});
  geometry.set_mesh_file("meshes/missing.stl");
  ExpectError([&] { GeometryFromProto("geometry", geometry, NoFile, limits); }, ErrorCode::kInvalidArgument,
              {"geometry.mesh_file", "meshes/missing.stl", "not uploaded"});
  geometry.mutable_cylinder()->set_radius(0.02);
  geometry.mutable_cylinder()->set_length(0.1);
  const Geometry cylinder = GeometryFromProto("geometry", geometry, NoFile, limits);
  EXPECT_EQ(cylinder.kind, Geometry::Kind::kCylinder);
  EXPECT_DOUBLE_EQ(cylinder.length, 0.1);
}

TEST(ConvertGeometry, InlineMeshIsScaledPerAxis) {
  Limits limits;
  v1::Geometry geometry;
  *geometry.mutable_mesh() = PackedMesh({0, 0, 0, 1, 0, 0, 0, 1, 1}, {0, 1, 2});
  geometry.mutable_scale()->set_x(2);
  geometry.mutable_scale()->set_y(3);
  geometry.mutable_scale()->set_z(0.5);
  const Geometry mesh = GeometryFromProto("geometry", geometry, NoFile, limits);
  EXPECT_EQ(mesh.mesh->vertices[1], Eigen::Vector3f(2, 0, 0));
  EXPECT_EQ(mesh.mesh->vertices[2], Eigen::Vector3f(0, 3, 0.5));
  geometry.mutable_scale()->set_z(-1);
  ExpectError([&] { GeometryFromProto("geometry", geometry, NoFile, limits); }, ErrorCode::kInvalidArgument,
              {"geometry.scale.z"});
}

}  // namespace
}  // namespace graspsim::rpc
