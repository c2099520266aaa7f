// The typed edit API (edits/scene_edits.h): every check names the record's field, materials lay over the body's
// own, shapes are scaled and loaded as the API documents, and the records journaled (edit_codec.h) decode to the
// same record, so that a replay builds the same model.
#include "edits/scene_edits.h"

#include <cmath>

#include <gtest/gtest.h>

#include "core/error.h"
#include "edits/edit_codec.h"
#include "graspsim/v1/scene.pb.h"
#include "test_util.h"
#include "world/scene_registry.h"

namespace graspsim::edits {
namespace {

using test_util::ExpectError;

const std::string* NoFile(const std::string&) { return nullptr; }

std::shared_ptr<const TriangleMesh> Triangle() {
  auto mesh = std::make_shared<TriangleMesh>();
  mesh->vertices = {{0, 0, 0}, {1, 0, 0}, {0, 1, 1}};
  mesh->triangles = {{0, 1, 2}};
  return mesh;
}

ShapeSpec Shape(Geometry::Kind kind) {
  ShapeSpec shape;
  shape.kind = kind;
  return shape;
}

AddObjectEdit BuiltinCube(const std::string& name) {
  AddObjectEdit edit;
  edit.name = name;
  edit.builtin = "cube_5cm";
  return edit;
}

TEST(ShapeGeometryTest, SizesMustBePositiveAndFilesUploaded) {
  Limits limits;
  ShapeSpec box = Shape(Geometry::Kind::kBox);
  box.box_size = Vec3(0.1, 0.1, 0);
  ExpectError([&] { ShapeGeometry("geometry", box, NoFile, limits); }, ErrorCode::kInvalidArgument,
              {"geometry.box.size.z"});
  ShapeSpec sphere = Shape(Geometry::Kind::kSphere);
  sphere.radius = NAN;
  ExpectError([&] { ShapeGeometry("geometry", sphere, NoFile, limits); }, ErrorCode::kInvalidArgument,
              {"geometry.sphere.radius", "nan"});
  ShapeSpec file = Shape(Geometry::Kind::kMesh);
  file.mesh_file = "meshes/missing.stl";
  ExpectError([&] { ShapeGeometry("geometry", file, NoFile, limits); }, ErrorCode::kInvalidArgument,
              {"geometry.mesh_file", "meshes/missing.stl", "not uploaded"});
  file.mesh_file = "../outside.stl";
  ExpectError([&] { ShapeGeometry("geometry", file, NoFile, limits); }, ErrorCode::kInvalidArgument,
              {"geometry.mesh_file"});
  ShapeSpec cylinder = Shape(Geometry::Kind::kCylinder);
  cylinder.radius = 0.02;
  cylinder.length = 0.1;
  const Geometry made = ShapeGeometry("geometry", cylinder, NoFile, limits);
  EXPECT_EQ(made.kind, Geometry::Kind::kCylinder);
  EXPECT_DOUBLE_EQ(made.length, 0.1);
}

TEST(ShapeGeometryTest, AnInlineMeshIsCheckedAndScaledPerAxis) {
  Limits limits;
  ShapeSpec shape = Shape(Geometry::Kind::kMesh);
  shape.mesh = Triangle();
  shape.scale = Vec3(2, 3, 0.5);
  const Geometry mesh = ShapeGeometry("geometry", shape, NoFile, limits);
  EXPECT_EQ(mesh.mesh->vertices[1], Eigen::Vector3f(2, 0, 0));
  EXPECT_EQ(mesh.mesh->vertices[2], Eigen::Vector3f(0, 3, 0.5));
  EXPECT_EQ(shape.mesh->vertices[1], Eigen::Vector3f(1, 0, 0));  // the record's mesh is not changed
  shape.scale.z() = -1;
  ExpectError([&] { ShapeGeometry("geometry", shape, NoFile, limits); }, ErrorCode::kInvalidArgument,
              {"geometry.scale.z"});
  shape.scale.z() = 1;
  auto bad = std::make_shared<TriangleMesh>(*Triangle());
  bad->triangles[0][2] = 7;
  shape.mesh = bad;
  ExpectError([&] { ShapeGeometry("geometry", shape, NoFile, limits); }, ErrorCode::kInvalidArgument,
              {"geometry.mesh", "index 7"});
}

TEST(AddObjectTest, MaterialLaysOverTheBodysOwnAndIsChecked) {
  Limits limits;
  SceneRegistry registry(limits);
  auto scene = registry.Create("s");
  AddObjectEdit cube = BuiltinCube("cube");
  cube.material.emplace();
  cube.material->contact_stiffness = 2e4;  // contact fields only: friction stays the built-in's
  const BodySpec added = AddObject(scene.get(), cube, limits).body;
  EXPECT_EQ(added.material.contact_stiffness, 2e4);
  EXPECT_NE(added.material.static_friction, 0);
  cube.name = "frictionless";
  cube.material->static_friction = 0;
  cube.material->dynamic_friction = 0;
  EXPECT_EQ(AddObject(scene.get(), cube, limits).body.material.static_friction, 0);
  cube.name = "refused";
  cube.material->static_friction = 0.3;
  cube.material->dynamic_friction = 0.5;
  ExpectError([&] { AddObject(scene.get(), cube, limits); }, ErrorCode::kInvalidArgument,
              {"material", "static_friction 0.3", "dynamic_friction 0.5"});
  cube.material->dynamic_friction = -0.1;
  ExpectError([&] { AddObject(scene.get(), cube, limits); }, ErrorCode::kInvalidArgument,
              {"material.dynamic_friction"});
  EXPECT_EQ(scene->View().model->body_index.count("refused"), 0u);
}

TEST(AddObjectTest, ExactlyOneSourceAndAValidInertial) {
  Limits limits;
  SceneRegistry registry(limits);
  auto scene = registry.Create("s");
  AddObjectEdit none;
  none.name = "none";
  ExpectError([&] { AddObject(scene.get(), none, limits); }, ErrorCode::kInvalidArgument, {"source"});
  AddObjectEdit both = BuiltinCube("both");
  both.shape = Shape(Geometry::Kind::kSphere);
  ExpectError([&] { AddObject(scene.get(), both, limits); }, ErrorCode::kInvalidArgument, {"source"});
  AddObjectEdit heavy = BuiltinCube("heavy");
  heavy.inertial = Inertial{-1, Vec3::Zero(), Mat3::Identity()};
  ExpectError([&] { AddObject(scene.get(), heavy, limits); }, ErrorCode::kInvalidArgument, {"inertial.mass"});
  AddObjectEdit unknown = BuiltinCube("unknown");
  unknown.builtin = "no_such_model";
  ExpectError([&] { AddObject(scene.get(), unknown, limits); }, ErrorCode::kNotFound, {"no_such_model"});
  EXPECT_TRUE(scene->View().model->bodies.empty());
}

TEST(UniformSolidObjectTest, TheBodyFrameIsAtTheCentroidWithTheSolidsInertia) {
  // A 2 × 1 × 1 box from (0,0,0) to (2,1,1) as a closed mesh: centroid (1, 0.5, 0.5), Ixx = m (b² + c²) / 12.
  TriangleMesh box;
  for (int i = 0; i < 8; ++i) box.vertices.emplace_back(2.0f * (i & 1), (i >> 1) & 1, (i >> 2) & 1);
  box.triangles = {{0, 2, 1}, {1, 2, 3}, {4, 5, 6}, {5, 7, 6}, {0, 1, 4}, {1, 5, 4},
                   {2, 6, 3}, {3, 6, 7}, {0, 4, 2}, {2, 4, 6}, {1, 3, 5}, {3, 7, 5}};
  const AddObjectEdit edit = UniformSolidObject("add_to_scene_id", "done", box, 3.0);
  EXPECT_TRUE(edit.pose.position.isApprox(Vec3(1, 0.5, 0.5), 1e-12));
  EXPECT_NEAR(edit.inertial->inertia(0, 0), 3.0 * (1 + 1) / 12, 1e-12);
  EXPECT_NEAR(edit.inertial->inertia(2, 2), 3.0 * (4 + 1) / 12, 1e-12);
  EXPECT_NEAR(edit.inertial->inertia(0, 1), 0, 1e-12);
  TriangleMesh flat;
  flat.vertices = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  flat.triangles = {{0, 1, 2}, {0, 2, 1}};
  ExpectError([&] { UniformSolidObject("add_to_scene_id", "flat", flat, 1.0); }, ErrorCode::kInvalidArgument,
              {"add_to_scene_id", "no volume"});
}

// Every field of every record survives the journal: a replayed record is the record.
TEST(EditCodecTest, EveryRecordRoundTrips) {
  AddObjectEdit object;
  object.name = "o";
  object.pose = Pose{Vec3(1, 2, 3), Quat(0.5, 0.5, 0.5, 0.5)};
  object.is_static = true;
  object.shape = Shape(Geometry::Kind::kMesh);
  object.shape->mesh = Triangle();
  object.shape->scale = Vec3(1, 2, 3);
  object.shape->origin.position = Vec3(0.1, 0, 0);
  object.inertial = Inertial{0.5, Vec3(0.01, 0, 0), Mat3::Identity() * 2e-3};
  object.material.emplace();
  object.material->static_friction = 0.8;
  object.material->stribeck_velocity = 2e-3;
  object.import_options.inertia = InertiaSource::kFromGeometry;
  object.import_options.density = 700;
  AddRobotEdit robot;
  robot.name = "r";
  robot.format = RobotFormat::kMjcf;
  robot.source = "<mujoco/>";
  robot.files["m/a.stl"] = std::make_shared<const std::string>(std::string("\0\x01\xff", 3));
  robot.import_options.strict = true;
  robot.import_options.model_name = "m";
  SetSimulationParamsEdit params;
  params.params.time_step = 5e-4;
  params.params.integrator = Integrator::kRungeKutta4;
  params.params.engine = PhysicsEngineKind::kBullet;
  params.params.contact.stribeck_velocity = 0.02;
  params.params.divergence_speed = 77;

  const auto again = [](const Edit& edit) { return DecodeEdit(EncodeEdit(edit)); };
  const auto o = std::get<AddObjectEdit>(again(object));
  EXPECT_EQ(o.name, "o");
  EXPECT_TRUE(o.pose.orientation.isApprox(object.pose.orientation));
  EXPECT_EQ(o.pose.position, object.pose.position);
  EXPECT_TRUE(o.is_static);
  EXPECT_EQ(o.shape->mesh->vertices, object.shape->mesh->vertices);
  EXPECT_EQ(o.shape->mesh->triangles, object.shape->mesh->triangles);
  EXPECT_EQ(o.shape->scale, object.shape->scale);
  EXPECT_EQ(o.shape->origin.position, object.shape->origin.position);
  EXPECT_EQ(o.inertial->inertia, object.inertial->inertia);
  EXPECT_EQ(o.inertial->center_of_mass, object.inertial->center_of_mass);
  EXPECT_EQ(o.material->static_friction, 0.8);
  EXPECT_FALSE(o.material->dynamic_friction.has_value());
  EXPECT_EQ(o.material->stribeck_velocity, 2e-3);
  EXPECT_EQ(o.import_options.inertia, InertiaSource::kFromGeometry);
  EXPECT_EQ(o.import_options.density, 700);
  const auto r = std::get<AddRobotEdit>(again(robot));
  EXPECT_EQ(r.format, RobotFormat::kMjcf);
  EXPECT_EQ(r.source, "<mujoco/>");
  EXPECT_EQ(*r.files.at("m/a.stl"), std::string("\0\x01\xff", 3));
  EXPECT_TRUE(r.import_options.strict);
  EXPECT_EQ(r.import_options.model_name, "m");
  EXPECT_EQ(std::get<RemoveBodyEdit>(again(RemoveBodyEdit{"gone"})).id, "gone");
  const auto p = std::get<SetSimulationParamsEdit>(again(params)).params;
  EXPECT_EQ(p.time_step, 5e-4);
  EXPECT_EQ(p.integrator, Integrator::kRungeKutta4);
  EXPECT_EQ(p.engine, PhysicsEngineKind::kBullet);
  EXPECT_EQ(p.contact.stribeck_velocity, 0.02);
  EXPECT_EQ(p.divergence_speed, 77);
  EXPECT_EQ(p.gravity, SimulationParams().gravity);
}

TEST(EditCodecTest, RecordsAndVersionOneRequestsCannotBeConfused) {
  const SceneOp op = EncodeEdit(RemoveBodyEdit{"gone"});
  EXPECT_TRUE(IsEditRecord(op));
  EXPECT_EQ(op.kind, "RemoveBody");
  // A record is not a request: protobuf refuses its first byte (wire type 7).
  v1::RemoveBodyRequest request;
  EXPECT_FALSE(request.ParseFromString(op.payload));
  // And a request is not a record.
  request.set_scene_id("scene-1");
  request.set_id("gone");
  SceneOp legacy;
  legacy.kind = "RemoveBody";
  legacy.payload = request.SerializeAsString();
  EXPECT_FALSE(IsEditRecord(legacy));
}

TEST(EditCodecTest, ABadRecordIsAnInternalErrorNamingWhatIsWrong) {
  SceneOp op = EncodeEdit(RemoveBodyEdit{"gone"});
  SceneOp newer = op;
  newer.payload[6] = 3;
  ExpectError([&] { DecodeEdit(newer); }, ErrorCode::kInternal, {"version 3"});
  SceneOp truncated = op;
  truncated.payload.resize(truncated.payload.size() - 2);
  ExpectError([&] { DecodeEdit(truncated); }, ErrorCode::kInternal, {"RemoveBody"});
  SceneOp wrong_kind = op;
  wrong_kind.kind = "AddObject";  // the fields of another record
  ExpectError([&] { DecodeEdit(wrong_kind); }, ErrorCode::kInternal, {"AddObject"});
  SceneOp unknown = op;
  unknown.kind = "Teleport";
  ExpectError([&] { DecodeEdit(unknown); }, ErrorCode::kInternal, {"Teleport"});
}

}  // namespace
}  // namespace graspsim::edits
