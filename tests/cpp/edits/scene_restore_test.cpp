// Scenes rebuilt on start (edits/scene_restore.h) are the scenes that were journaled: same ids, names, bodies,
// joints, files, parameters, state and revision; an edit whose journal write fails changes nothing. The scenes
// are built through the typed edit API (edits/scene_edits.h), so every op here is an edit record; version-1 ops
// (serialized requests) are tested with a stored fixture in tests/python/test_old_journals.py.
#include <filesystem>

#include <gtest/gtest.h>

#include "core/error.h"
#include "core/sha256.h"
#include "persistence/scene_store.h"
#include "persistence/state_codec.h"
#include "edits/scene_edits.h"
#include "edits/scene_restore.h"
#include "test_util.h"

namespace graspsim::edits {
namespace {

namespace fs = std::filesystem;

// A two-link arm whose second link is the uploaded mesh.
const char* kArmUrdf = R"(<?xml version="1.0"?>
<robot name="arm">
  <link name="base"><inertial><mass value="1"/><inertia ixx="1e-3" iyy="1e-3" izz="1e-3" ixy="0" ixz="0" iyz="0"/>
    </inertial><collision><geometry><box size="0.1 0.1 0.1"/></geometry></collision></link>
  <link name="arm"><inertial><mass value="0.5"/><inertia ixx="1e-3" iyy="1e-3" izz="1e-3" ixy="0" ixz="0" iyz="0"/>
    </inertial><collision><geometry><mesh filename="package://arm/tet.obj"/></geometry></collision></link>
  <joint name="shoulder" type="revolute"><parent link="base"/><child link="arm"/><origin xyz="0 0 0.1"/>
    <axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="10" velocity="1"/></joint>
</robot>
)";
const char* kTetObj = "v 0 0 0\nv 0.1 0 0\nv 0 0.1 0\nv 0 0 0.1\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n";

void Upload(Scene* scene, const std::string& path, const std::string& bytes) {
  SceneOp op;
  op.kind = "UploadFile";
  op.path = path;
  op.sha256 = Sha256Hex(bytes);
  op.file = std::make_shared<const std::string>(bytes);
  scene->PutFile(path, op.file, op.sha256, &op);
}

// No op in these scenes is a version-1 request.
Edit NoLegacyOps(const SceneOp& op) { throw Error(ErrorCode::kInternal, "a version-1 op: " + op.kind); }

AddObjectEdit Builtin(const std::string& name, const std::string& builtin) {
  AddObjectEdit edit;
  edit.name = name;
  edit.builtin = builtin;
  edit.pose.position.z() = 0.5;
  return edit;
}

// Builds a scene of every kind of edit.
void BuildScene(Scene* scene, const Limits& limits) {
  Upload(scene, "tet.obj", kTetObj);
  AddRobotEdit robot;
  robot.name = "arm";
  robot.source = kArmUrdf;
  AddRobot(scene, robot, limits);
  for (const char* name : {"cube", "gone"}) AddObject(scene, Builtin(name, "cube_5cm"), limits);
  AddObjectEdit mesh;
  mesh.name = "tet";
  mesh.shape.emplace();
  mesh.shape->kind = Geometry::Kind::kMesh;
  mesh.shape->mesh_file = "tet.obj";
  mesh.inertial = Inertial{0.2, Vec3::Zero(), Mat3::Identity() * 1e-4};
  AddObject(scene, mesh, limits);
  RemoveBody(scene, {"gone"});
  SetSimulationParamsEdit params;
  params.params.time_step = 2e-3;
  params.params.gravity = Vec3(0, 0, -1.62);
  SetSimulationParams(scene, params);
  Pose moved;
  moved.position = Vec3(0.3, 0.2, 0.1);
  scene->SetBodyPoses({{"cube", moved}});
  scene->SetJointPositions({{"arm/shoulder", 0.4}});
  // A simulation-like change that is journaled only by the checkpoint.
  scene->Update([](const std::shared_ptr<const SceneModel>&, SceneState* state) { state->time = 0.5; }, false);
  scene->Checkpoint();
}

TEST(SceneRestoreTest, ARestartServesTheScenesThatWereStored) {
  const test_util::TempDir temp("restore-test", /*create=*/false);
  const std::string dir = temp.str();
  Limits limits;
  SceneView before, empty_before;
  std::string deleted_id;
  {
    persistence::SceneStore store(dir);
    SceneRegistry registry(limits);
    ASSERT_EQ(RestoreScenes(&store, &registry, NoLegacyOps), 0u);
    auto scene = registry.Create("everything");
    BuildScene(scene.get(), limits);
    empty_before = registry.Create("empty")->View();
    deleted_id = registry.Create("deleted")->id();
    registry.Delete(deleted_id);
    registry.Create("chosen", "client-chosen-id");
    before = scene->View();
  }
  persistence::SceneStore store(dir);
  SceneRegistry registry(limits);
  ASSERT_EQ(RestoreScenes(&store, &registry, NoLegacyOps), 3u);
  EXPECT_EQ(registry.Get("client-chosen-id")->View().name, "chosen");
  const SceneView after = registry.Get(before.id)->View();
  EXPECT_EQ(after.name, "everything");
  EXPECT_EQ(after.revision, before.revision);
  ASSERT_EQ(after.model->bodies.size(), before.model->bodies.size());
  for (size_t i = 0; i < after.model->bodies.size(); ++i) {
    EXPECT_EQ(after.model->bodies[i].id, before.model->bodies[i].id);
    EXPECT_EQ(after.model->bodies[i].inertial.mass, before.model->bodies[i].inertial.mass);
  }
  ASSERT_EQ(after.model->joints.size(), 1u);
  EXPECT_EQ(after.model->joints[0].id, "arm/shoulder");
  EXPECT_EQ(after.model->body_index.count("gone"), 0u);
  EXPECT_EQ(after.model->simulation.time_step, 2e-3);
  EXPECT_EQ(after.model->simulation.gravity, Vec3(0, 0, -1.62));
  EXPECT_EQ(persistence::EncodeState(after.state), persistence::EncodeState(before.state));
  EXPECT_EQ(after.state.time, 0.5);
  EXPECT_EQ(after.state.joint_positions[0], 0.4);
  ASSERT_EQ(after.files.size(), 1u);
  EXPECT_EQ(*after.files.at("tet.obj").bytes, kTetObj);
  const auto& tet = after.model->bodies[after.model->body_index.at("tet")].collision.at(0);
  ASSERT_TRUE(tet.mesh);
  EXPECT_EQ(tet.mesh->triangles.size(), 4u);
  EXPECT_EQ(registry.Get(empty_before.id)->View().name, "empty");
  test_util::ExpectError([&] { registry.Get(deleted_id); }, ErrorCode::kNotFound, {deleted_id.c_str()});
  // Ids go on after the highest ever handed out, the deleted scene's included.
  EXPECT_EQ(registry.Create("next")->id(), "scene-4");
}

class FailingStore : public persistence::SceneStore {
 public:
  using SceneStore::SceneStore;
  bool fail = false;

 protected:
  void BeforeCommit() override {
    if (fail) throw Error(ErrorCode::kInternal, "disk full (injected)");
  }
};

TEST(SceneRestoreTest, AnEditWhoseJournalWriteFailsChangesNothing) {
  const test_util::TempDir temp("restore-test", /*create=*/false);
  const std::string dir = temp.str();
  Limits limits;
  {
    FailingStore store(dir);
    SceneRegistry registry(limits);
    RestoreScenes(&store, &registry, NoLegacyOps);
    auto scene = registry.Create("s");
    BuildScene(scene.get(), limits);
    const SceneView before = scene->View();
    store.fail = true;
    test_util::ExpectError([&] { AddObject(scene.get(), Builtin("late", "cube_5cm"), limits); },
                           ErrorCode::kInternal, {"injected"});
    test_util::ExpectError([&] { scene->SetJointPositions({{"arm/shoulder", -0.4}}); }, ErrorCode::kInternal,
                           {"injected"});
    test_util::ExpectError([&] { Upload(scene.get(), "late.obj", kTetObj); }, ErrorCode::kInternal, {"injected"});
    test_util::ExpectError([&] { registry.Delete(scene->id()); }, ErrorCode::kInternal, {"injected"});
    const SceneView after = scene->View();
    EXPECT_EQ(after.revision, before.revision);
    EXPECT_EQ(after.model, before.model);  // the same model object: nothing was swapped in
    EXPECT_EQ(after.files.size(), 1u);
    EXPECT_EQ(persistence::EncodeState(after.state), persistence::EncodeState(before.state));
    EXPECT_NO_THROW(registry.Get(scene->id()));
  }
}

}  // namespace
}  // namespace graspsim::edits

namespace graspsim::edits {
namespace {

// A scene moved by archive (ExportScene → ImportScene) is the scene: same bodies, files, state; the copy is
// journaled at its new home, so it survives that server's restart too.
TEST(SceneArchiveTest, AnImportedSceneIsTheExportedOneAndSurvivesARestart) {
  Limits limits;
  SceneRegistry source(limits);
  auto scene = source.Create("everything", "moving-scene");
  BuildScene(scene.get(), limits);
  const SceneView before = scene->View();
  const std::string bytes = persistence::EncodeSceneArchive(ArchiveOf(*scene));

  const test_util::TempDir temp("restore-test", /*create=*/false);
  const std::string dir = temp.str();
  {
    persistence::SceneStore store(dir);
    SceneRegistry target(limits);
    RestoreScenes(&store, &target, NoLegacyOps);
    const auto copy = ImportArchive(persistence::DecodeSceneArchive(bytes, "data"), "", &target, NoLegacyOps);
    EXPECT_EQ(copy->id(), "moving-scene");
    EXPECT_EQ(persistence::EncodeState(copy->View().state), persistence::EncodeState(before.state));
    EXPECT_GT(copy->revision(), 0u);
    test_util::ExpectError([&] { ImportArchive(persistence::DecodeSceneArchive(bytes, "data"), "", &target, NoLegacyOps); },
                           ErrorCode::kAlreadyExists, {"moving-scene"});
    EXPECT_EQ(ImportArchive(persistence::DecodeSceneArchive(bytes, "data"), "second-copy", &target, NoLegacyOps)->id(),
              "second-copy");
  }
  persistence::SceneStore store(dir);
  SceneRegistry restarted(limits);
  ASSERT_EQ(RestoreScenes(&store, &restarted, NoLegacyOps), 2u);
  const SceneView after = restarted.Get("moving-scene")->View();
  EXPECT_EQ(after.name, "everything");
  ASSERT_EQ(after.model->bodies.size(), before.model->bodies.size());
  for (size_t i = 0; i < after.model->bodies.size(); ++i) EXPECT_EQ(after.model->bodies[i].id, before.model->bodies[i].id);
  EXPECT_EQ(after.model->simulation.gravity, Vec3(0, 0, -1.62));
  EXPECT_EQ(persistence::EncodeState(after.state), persistence::EncodeState(before.state));
  EXPECT_EQ(*after.files.at("tet.obj").bytes, kTetObj);
}

// Bad archives are refused naming the field, and leave no scene behind.
TEST(SceneArchiveTest, ABadArchiveIsRefusedAndChangesNothing) {
  Limits limits;
  SceneRegistry source(limits);
  auto scene = source.Create("s");
  BuildScene(scene.get(), limits);
  persistence::SceneArchive archive = ArchiveOf(*scene);
  const std::string bytes = persistence::EncodeSceneArchive(archive);
  using test_util::ExpectError;
  ExpectError([&] { persistence::DecodeSceneArchive("not an archive", "data"); }, ErrorCode::kInvalidArgument,
              {"data", "GSSCENE"});
  ExpectError([&] { persistence::DecodeSceneArchive(bytes.substr(0, bytes.size() - 10), "data"); },
              ErrorCode::kInvalidArgument, {"data", "truncated"});
  ExpectError([&] { persistence::DecodeSceneArchive(bytes + "x", "data"); }, ErrorCode::kInvalidArgument,
              {"data", "after the end"});
  std::string tampered = bytes;
  tampered[tampered.find("v 0.1 0 0")] = 'w';  // the uploaded file's bytes, no longer its SHA-256
  ExpectError([&] { persistence::DecodeSceneArchive(tampered, "data"); }, ErrorCode::kInvalidArgument,
              {"tet.obj", "SHA-256"});

  SceneRegistry target(limits);
  archive.ops.erase(archive.ops.begin());  // the robot's mesh file is gone: its AddRobot cannot apply
  ExpectError([&] { ImportArchive(archive, "", &target, NoLegacyOps); }, ErrorCode::kInvalidArgument, {"data", "edit 1", "AddRobot"});
  EXPECT_TRUE(target.List().empty());
}

}  // namespace
}  // namespace graspsim::edits
