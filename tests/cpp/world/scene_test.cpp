// Scene edits: all-or-nothing, limits, ids, forward kinematics against hand-computed poses.
#include "world/scene.h"

#include <cmath>

#include <gtest/gtest.h>

#include "test_util.h"
#include "world/scene_registry.h"

namespace graspsim {
namespace {

using test_util::ExpectError;

BodySpec Box(const std::string& id, BodyMotion motion = BodyMotion::kFree) {
  BodySpec body;
  body.id = id;
  body.motion = motion;
  Geometry box;
  box.box_size = Vec3(0.05, 0.05, 0.05);
  body.collision.push_back(box);
  body.inertial.mass = 0.1;
  body.inertial.inertia = Mat3::Identity() * (0.1 * 0.05 * 0.05 / 6);
  return body;
}

// A gripper: base, two fingers on prismatic joints along +y and -y at 0.1 m in front of the base; the right
// finger mimics the left one.
RobotDescription Gripper() {
  RobotDescription robot;
  robot.name = "gripper";
  robot.root_link = "base";
  for (const char* link : {"base", "left", "right"}) robot.links.push_back(Box(link, BodyMotion::kArticulated));
  JointSpec left;
  left.id = "left_joint";
  left.type = JointType::kPrismatic;
  left.parent_body = "base";
  left.child_body = "left";
  left.origin.position = Vec3(0, 0, 0.1);
  left.axis = Vec3::UnitY();
  left.lower = 0;
  left.upper = 0.035;
  JointSpec right = left;
  right.id = "right_joint";
  right.child_body = "right";
  right.axis = -Vec3::UnitY();
  right.mimic = MimicSpec{"left_joint", 1.0, 0.0};
  robot.joints = {left, right};
  TactileArraySpec pad;
  pad.id = "pad";
  pad.body_id = "left";
  pad.rows = 14;
  pad.cols = 6;
  pad.pitch = 0.0034;
  pad.thickness = 0.004;
  robot.tactile_arrays = {pad};
  return robot;
}

Pose At(double x, double y, double z, const Quat& q = Quat::Identity()) { return {Vec3(x, y, z), q}; }

class SceneTest : public ::testing::Test {
 protected:
  Pose PoseOf(const std::string& id) {
    const SceneView view = scene_.View();
    return view.state.body_poses[view.model->body_index.at(id)];
  }
  double JointOf(const std::string& id) {
    const SceneView view = scene_.View();
    return view.state.joint_positions[view.model->joint_index.at(id)];
  }

  Limits limits_;
  Scene scene_{"scene-1", "test", limits_};
};

TEST_F(SceneTest, AddObjectStoresPoseAndBumpsRevision) {
  const uint64_t before = scene_.revision();
  scene_.AddObject(Box("cube"), At(0.1, 0.2, 0.3));
  EXPECT_EQ(scene_.revision(), before + 1);
  EXPECT_TRUE(PoseOf("cube").position.isApprox(Vec3(0.1, 0.2, 0.3)));
}

TEST_F(SceneTest, DuplicateIdIsRejectedAndNothingChanges) {
  scene_.AddObject(Box("cube"), At(0, 0, 0));
  const uint64_t revision = scene_.revision();
  ExpectError([&] { scene_.AddObject(Box("cube"), At(1, 1, 1)); }, ErrorCode::kAlreadyExists, {"'cube'"});
  EXPECT_EQ(scene_.revision(), revision);
  EXPECT_TRUE(PoseOf("cube").position.isZero());
  // A robot may not take an object's name either.
  ExpectError([&] { scene_.AddRobot("cube", "urdf", Gripper(), {}); }, ErrorCode::kAlreadyExists, {"'cube'"});
}

TEST_F(SceneTest, BodyLimitCountsRobotLinks) {
  limits_.max_bodies_per_scene = 3;
  Scene scene("scene-2", "limited", limits_);
  scene.AddObject(Box("a"), {});
  ExpectError([&] { scene.AddRobot("g", "urdf", Gripper(), {}); }, ErrorCode::kResourceExhausted, {"limit of 3"});
  scene.AddObject(Box("b"), {});
  scene.AddObject(Box("c"), {});
  ExpectError([&] { scene.AddObject(Box("d"), {}); }, ErrorCode::kResourceExhausted, {"'d'", "3"});
  EXPECT_EQ(scene.View().model->bodies.size(), 3u);
}

TEST_F(SceneTest, RobotIdsArePrefixedAndLinksPlacedByForwardKinematics) {
  // Base rotated 90 deg about x: its +y (finger axis) becomes world +z, its +z (approach) becomes world -y.
  const Quat base_rotation(Eigen::AngleAxisd(M_PI / 2, Vec3::UnitX()));
  const AddedRobot added = scene_.AddRobot("g", "urdf", Gripper(), At(1, 2, 3, base_rotation));
  EXPECT_EQ(added.robot.base_body, "g/base");
  EXPECT_EQ(added.joints[1].mimic->joint_id, "g/left_joint");
  EXPECT_EQ(added.tactile_arrays[0].body_id, "g/left");
  scene_.SetJointPositions({{"g/left_joint", 0.02}});
  EXPECT_DOUBLE_EQ(JointOf("g/right_joint"), 0.02);
  // left = base * (0, 0.02, 0.1) in base coordinates = (1, 2, 3) + R_x(90)(0, 0.02, 0.1) = (1, 1.9, 3.02).
  EXPECT_LT((PoseOf("g/left").position - Vec3(1, 1.9, 3.02)).norm(), 1e-12);
  EXPECT_LT((PoseOf("g/right").position - Vec3(1, 1.9, 2.98)).norm(), 1e-12);
  EXPECT_LT(PoseOf("g/left").orientation.angularDistance(base_rotation), 1e-12);
}

TEST_F(SceneTest, MovingTheRobotMovesItsLinks) {
  scene_.AddRobot("g", "urdf", Gripper(), {});
  scene_.SetBodyPoses({{"g", At(0.5, 0, 0)}});
  EXPECT_LT((PoseOf("g/left").position - Vec3(0.5, 0, 0.1)).norm(), 1e-12);
  scene_.SetBodyPoses({{"g/base", At(0, 0.5, 0)}});
  EXPECT_LT((PoseOf("g/right").position - Vec3(0, 0.5, 0.1)).norm(), 1e-12);
}

TEST_F(SceneTest, LinksOtherThanTheBaseCannotBePosed) {
  scene_.AddRobot("g", "urdf", Gripper(), {});
  ExpectError([&] { scene_.SetBodyPoses({{"g/left", At(1, 0, 0)}}); }, ErrorCode::kFailedPrecondition,
              {"'g/left'", "'g'"});
}

TEST_F(SceneTest, PoseBatchIsAllOrNothing) {
  scene_.AddObject(Box("a"), At(0, 0, 0));
  const uint64_t revision = scene_.revision();
  ExpectError([&] { scene_.SetBodyPoses({{"a", At(1, 1, 1)}, {"missing", At(2, 2, 2)}}); }, ErrorCode::kNotFound,
              {"'missing'"});
  EXPECT_TRUE(PoseOf("a").position.isZero());
  EXPECT_EQ(scene_.revision(), revision);
}

TEST_F(SceneTest, JointBatchIsAllOrNothingAndLimitsAreChecked) {
  scene_.AddRobot("g", "urdf", Gripper(), {});
  scene_.SetJointPositions({{"g/left_joint", 0.01}});
  const uint64_t revision = scene_.revision();
  ExpectError([&] { scene_.SetJointPositions({{"g/left_joint", 0.05}}); }, ErrorCode::kInvalidArgument,
              {"g/left_joint", "0.05", "limits"});
  ExpectError([&] { scene_.SetJointPositions({{"g/left_joint", NAN}}); }, ErrorCode::kInvalidArgument, {"nan"});
  ExpectError([&] { scene_.SetJointPositions({{"g/right_joint", 0.02}}); }, ErrorCode::kInvalidArgument,
              {"mimics", "g/left_joint"});
  ExpectError([&] { scene_.SetJointPositions({{"g/nope", 0.0}}); }, ErrorCode::kNotFound, {"'g/nope'"});
  EXPECT_DOUBLE_EQ(JointOf("g/left_joint"), 0.01);
  EXPECT_DOUBLE_EQ(JointOf("g/right_joint"), 0.01);
  EXPECT_EQ(scene_.revision(), revision);
}

TEST_F(SceneTest, RemoveTakesObjectsAndWholeRobotsAndKeepsTheRestInPlace) {
  scene_.AddObject(Box("a"), At(1, 0, 0));
  scene_.AddRobot("g", "urdf", Gripper(), At(0, 0, 1));
  scene_.AddObject(Box("b"), At(2, 0, 0));
  ExpectError([&] { scene_.Remove("g/left"); }, ErrorCode::kFailedPrecondition, {"remove the whole robot"});
  ExpectError([&] { scene_.Remove("zzz"); }, ErrorCode::kNotFound, {"'zzz'"});
  EXPECT_EQ(scene_.Remove("g"), (std::vector<std::string>{"g/base", "g/left", "g/right"}));
  const SceneView view = scene_.View();
  EXPECT_EQ(view.model->bodies.size(), 2u);
  EXPECT_TRUE(view.model->joints.empty());
  EXPECT_TRUE(view.model->tactile_arrays.empty());
  EXPECT_TRUE(view.model->robots.empty());
  EXPECT_TRUE(PoseOf("b").position.isApprox(Vec3(2, 0, 0)));
  scene_.Remove("a");
  EXPECT_TRUE(PoseOf("b").position.isApprox(Vec3(2, 0, 0)));
}

TEST_F(SceneTest, FilesCountAgainstTheSceneLimitAndReplace) {
  limits_.max_scene_file_bytes = 10;
  Scene scene("scene-3", "files", limits_);
  scene.PutFile("a.stl", std::make_shared<const std::string>(6, 'x'), "h1");
  scene.PutFile("a.stl", std::make_shared<const std::string>(8, 'y'), "h2");  // replaces: 8 bytes in all
  ExpectError([&] { scene.PutFile("b.stl", std::make_shared<const std::string>(3, 'z'), "h3"); },
              ErrorCode::kResourceExhausted, {"'b.stl'", "11 bytes"});
  EXPECT_EQ(scene.Files().size(), 1u);
  EXPECT_EQ(scene.Files().at("a.stl").sha256, "h2");
}

class CountingWatcher : public SnapshotWatcher {
 public:
  void OnSnapshotAvailable() override { ++available; }
  void OnHubClosed(const std::string& why) override { reason = why; }
  int available = 0;
  std::string reason;
};

TEST_F(SceneTest, EveryCommitPublishesANewerSnapshot) {
  auto watcher = std::make_shared<CountingWatcher>();
  ASSERT_TRUE(scene_.snapshots().Subscribe(watcher));
  const uint64_t first = scene_.snapshots().Latest()->sequence;
  scene_.AddObject(Box("a"), At(0, 0, 0));
  scene_.SetBodyPoses({{"a", At(0, 0, 0.5)}});
  const auto latest = scene_.snapshots().Latest();
  EXPECT_EQ(watcher->available, 2);
  EXPECT_EQ(latest->sequence, first + 2);
  EXPECT_EQ(latest->revision, scene_.revision());
  ASSERT_EQ(latest->body_ids->size(), 1u);
  EXPECT_EQ(latest->body_poses, (std::vector<double>{0, 0, 0.5, 1, 0, 0, 0}));
  // A rejected edit publishes nothing.
  EXPECT_THROW(scene_.SetBodyPoses({{"nope", {}}}), Error);
  EXPECT_EQ(watcher->available, 2);
}

TEST(SceneRegistryTest, LimitsIdsAndDeletion) {
  Limits limits;
  limits.max_scenes = 2;
  SceneRegistry registry(limits);
  auto a = registry.Create("a");
  registry.Create("b");
  ExpectError([&] { registry.Create("c"); }, ErrorCode::kResourceExhausted, {"--max-scenes", "2"});
  ExpectError([&] { registry.Create(std::string(129, 'n')); }, ErrorCode::kInvalidArgument, {"128"});
  auto watcher = std::make_shared<CountingWatcher>();
  a->snapshots().Subscribe(watcher);
  registry.Delete(a->id());
  EXPECT_NE(watcher->reason.find("deleted"), std::string::npos);
  EXPECT_FALSE(a->snapshots().Subscribe(std::make_shared<CountingWatcher>()));
  ExpectError([&] { registry.Get(a->id()); }, ErrorCode::kNotFound, {a->id().c_str()});
  ExpectError([&] { registry.Delete(a->id()); }, ErrorCode::kNotFound, {"scene_id"});
  EXPECT_EQ(registry.List().size(), 1u);
  registry.Create("c");  // room again after the delete
}

// A fleet routes by the id before the scene exists (docs/scaling.md): the client may choose it.
TEST(SceneRegistryTest, TakesAClientChosenIdOnceAndKeepsItsOwnIdsUnique) {
  SceneRegistry registry(Limits{});
  EXPECT_EQ(registry.Create("mine", "lab-7.cell_2")->id(), "lab-7.cell_2");
  EXPECT_EQ(registry.Get("lab-7.cell_2")->View().name, "mine");
  ExpectError([&] { registry.Create("again", "lab-7.cell_2"); }, ErrorCode::kAlreadyExists, {"scene_id", "lab-7.cell_2"});
  ExpectError([&] { registry.Create("x", "scene-3"); }, ErrorCode::kInvalidArgument, {"scene_id", "scene-3", "scene-<n>"});
  ExpectError([&] { registry.Create("x", "a/b"); }, ErrorCode::kInvalidArgument, {"scene_id", "a/b"});
  ExpectError([&] { registry.Create("x", std::string(65, 'a')); }, ErrorCode::kInvalidArgument, {"scene_id", "1-64"});
  EXPECT_EQ(registry.List().size(), 1u) << "a refused creation changes nothing";
  EXPECT_EQ(registry.Create("generated")->id(), "scene-1") << "client ids do not use up the server's numbers";
  EXPECT_EQ(registry.Create("scene-x", "scene-x")->id(), "scene-x");
  // A scene moved from another server keeps its scene-<n> id; this server's own ids continue past it.
  EXPECT_EQ(registry.CreateMoved("moved", "scene-7")->id(), "scene-7");
  EXPECT_EQ(registry.Create("next")->id(), "scene-8");
  ExpectError([&] { registry.CreateMoved("again", "scene-7"); }, ErrorCode::kAlreadyExists, {"scene-7"});
}

TEST(KinematicsTest, RevoluteJointRotatesAboutItsAxis) {
  JointSpec joint;
  joint.type = JointType::kRevolute;
  joint.axis = Vec3::UnitZ();
  const Pose motion = JointMotion(joint, M_PI / 2);
  EXPECT_LT((motion * Vec3(1, 0, 0) - Vec3(0, 1, 0)).norm(), 1e-15);
  joint.type = JointType::kFixed;
  EXPECT_TRUE((JointMotion(joint, 1.0) * Vec3(1, 2, 3)).isApprox(Vec3(1, 2, 3)));
}

}  // namespace
}  // namespace graspsim
