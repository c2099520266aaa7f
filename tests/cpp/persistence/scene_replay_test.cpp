// Scenes rebuilt on start (rpc/scene_replay.h) are the scenes that were journaled: same ids, names, bodies,
// joints, files, parameters, state and revision; an edit whose journal write fails changes nothing.
#include <filesystem>
#include <random>

#include <gtest/gtest.h>

#include "core/error.h"
#include "core/sha256.h"
#include "persistence/scene_store.h"
#include "persistence/state_codec.h"
#include "rpc/scene_edits.h"
#include "rpc/scene_replay.h"
#include "test_util.h"

namespace graspsim::rpc {
namespace {

namespace fs = std::filesystem;

std::string TempDirectory() {
  std::random_device random;
  return (fs::temp_directory_path() / ("graspsim-replay-test-" + std::to_string(random()) + std::to_string(random())))
      .string();
}

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

// Builds a scene of every kind of edit, as the RPC handlers do.
void BuildScene(Scene* scene, const Limits& limits) {
  Upload(scene, "tet.obj", kTetObj);
  v1::AddRobotRequest robot;
  robot.set_name("arm");
  robot.set_urdf(kArmUrdf);
  robot.mutable_base_pose()->mutable_orientation()->set_w(1);
  AddRobotFromRequest(scene, robot, limits, nullptr);
  for (const char* name : {"cube", "gone"}) {
    v1::AddObjectRequest object;
    object.set_name(name);
    object.set_builtin("cube_5cm");
    object.mutable_pose()->mutable_position()->set_z(0.5);
    object.mutable_pose()->mutable_orientation()->set_w(1);
    AddObjectFromRequest(scene, object, limits, nullptr);
  }
  v1::AddObjectRequest mesh;
  mesh.set_name("tet");
  mesh.mutable_geometry()->set_mesh_file("tet.obj");
  auto* inertial = mesh.mutable_inertial();
  inertial->set_mass(0.2);
  inertial->set_ixx(1e-4);
  inertial->set_iyy(1e-4);
  inertial->set_izz(1e-4);
  mesh.mutable_pose()->mutable_orientation()->set_w(1);
  AddObjectFromRequest(scene, mesh, limits, nullptr);
  v1::RemoveBodyRequest remove;
  remove.set_id("gone");
  RemoveBodyFromRequest(scene, remove);
  v1::SetSimulationParamsRequest params;
  params.mutable_params()->set_time_step(2e-3);
  params.mutable_params()->mutable_gravity()->set_z(-1.62);
  SetSimulationParamsFromRequest(scene, params, nullptr);
  Pose moved;
  moved.position = Vec3(0.3, 0.2, 0.1);
  scene->SetBodyPoses({{"cube", moved}});
  scene->SetJointPositions({{"arm/shoulder", 0.4}});
  // A simulation-like change that is journaled only by the checkpoint.
  scene->Update([](const std::shared_ptr<const SceneModel>&, SceneState* state) { state->time = 0.5; }, false);
  scene->Checkpoint();
}

TEST(SceneReplayTest, ARestartServesTheScenesThatWereStored) {
  const std::string dir = TempDirectory();
  Limits limits;
  SceneView before, empty_before;
  std::string deleted_id;
  {
    persistence::SceneStore store(dir);
    SceneRegistry registry(limits);
    ASSERT_EQ(RestoreScenes(&store, &registry), 0u);
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
  ASSERT_EQ(RestoreScenes(&store, &registry), 3u);
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
  fs::remove_all(dir);
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

TEST(SceneReplayTest, AnEditWhoseJournalWriteFailsChangesNothing) {
  const std::string dir = TempDirectory();
  Limits limits;
  {
    FailingStore store(dir);
    SceneRegistry registry(limits);
    RestoreScenes(&store, &registry);
    auto scene = registry.Create("s");
    BuildScene(scene.get(), limits);
    const SceneView before = scene->View();
    store.fail = true;
    v1::AddObjectRequest object;
    object.set_name("late");
    object.set_builtin("cube_5cm");
    object.mutable_pose()->mutable_orientation()->set_w(1);
    test_util::ExpectError([&] { AddObjectFromRequest(scene.get(), object, limits, nullptr); }, ErrorCode::kInternal,
                           {"injected"});
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
  fs::remove_all(dir);
}

}  // namespace
}  // namespace graspsim::rpc

namespace graspsim::rpc {
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

  const std::string dir = TempDirectory();
  {
    persistence::SceneStore store(dir);
    SceneRegistry target(limits);
    RestoreScenes(&store, &target);
    const auto copy = ImportArchive(persistence::DecodeSceneArchive(bytes, "data"), "", &target);
    EXPECT_EQ(copy->id(), "moving-scene");
    EXPECT_EQ(persistence::EncodeState(copy->View().state), persistence::EncodeState(before.state));
    EXPECT_GT(copy->revision(), 0u);
    test_util::ExpectError([&] { ImportArchive(persistence::DecodeSceneArchive(bytes, "data"), "", &target); },
                           ErrorCode::kAlreadyExists, {"moving-scene"});
    EXPECT_EQ(ImportArchive(persistence::DecodeSceneArchive(bytes, "data"), "second-copy", &target)->id(),
              "second-copy");
  }
  persistence::SceneStore store(dir);
  SceneRegistry restarted(limits);
  ASSERT_EQ(RestoreScenes(&store, &restarted), 2u);
  const SceneView after = restarted.Get("moving-scene")->View();
  EXPECT_EQ(after.name, "everything");
  ASSERT_EQ(after.model->bodies.size(), before.model->bodies.size());
  for (size_t i = 0; i < after.model->bodies.size(); ++i) EXPECT_EQ(after.model->bodies[i].id, before.model->bodies[i].id);
  EXPECT_EQ(after.model->simulation.gravity, Vec3(0, 0, -1.62));
  EXPECT_EQ(persistence::EncodeState(after.state), persistence::EncodeState(before.state));
  EXPECT_EQ(*after.files.at("tet.obj").bytes, kTetObj);
  fs::remove_all(dir);
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
  ExpectError([&] { ImportArchive(archive, "", &target); }, ErrorCode::kInvalidArgument, {"data", "edit 1", "AddRobot"});
  EXPECT_TRUE(target.List().empty());
}

}  // namespace
}  // namespace graspsim::rpc
