// Scene::TryRead and SceneRegistry::TryGet, the no-wait reads that short calls make on gRPC's own threads
// (rpc/call.h RunShortRead): a scene read does not wait for a writer's journal commit (here one held open) and
// shows the stored state meanwhile; the registry gives up while a scene is being created; both read the same as
// View / Get otherwise.
#include <condition_variable>
#include <future>
#include <mutex>

#include <gtest/gtest.h>

#include "test_util.h"
#include "world/scene.h"
#include "world/scene_journal.h"
#include "world/scene_registry.h"

namespace graspsim {
namespace {

// A journal whose commits wait until released: a writer stuck in its transaction, holding the writers' lock.
class HeldJournal : public SceneJournal {
 public:
  void SceneCreated(const std::string&, const std::string&, uint64_t) override { Hold(); }
  void SceneDeleted(const std::string&) override { Hold(); }
  void SceneChanged(const std::string&, const SceneOp*, const SceneState&, uint64_t) override { Hold(); }

  void Arm() {
    std::lock_guard lock(mutex_);
    armed_ = true;
    entered_ = released_ = false;
  }
  void WaitEntered() {
    std::unique_lock lock(mutex_);
    changed_.wait(lock, [this] { return entered_; });
  }
  void Release() {
    std::lock_guard lock(mutex_);
    released_ = true;
    changed_.notify_all();
  }

 private:
  void Hold() {
    std::unique_lock lock(mutex_);
    if (!armed_) return;
    entered_ = true;
    changed_.notify_all();
    changed_.wait(lock, [this] { return released_; });
    armed_ = false;
  }
  std::mutex mutex_;
  std::condition_variable changed_;
  bool armed_ = false, entered_ = false, released_ = false;
};

Pose At(double x) {
  Pose pose;
  pose.position = Vec3(x, 0, 0);
  return pose;
}

BodySpec Ball(const std::string& id) {
  BodySpec body;
  body.id = id;
  Geometry ball;
  ball.kind = Geometry::Kind::kSphere;
  ball.radius = 0.01;
  body.collision.push_back(ball);
  body.inertial.mass = 0.01;
  body.inertial.inertia = Mat3::Identity() * 4e-7;
  return body;
}

TEST(SceneTryView, ReadsTheStoredStateWhileAWriterCommitsAndReadsLikeViewOtherwise) {
  Limits limits;
  SceneRegistry registry(limits);
  HeldJournal journal;
  registry.AttachJournal(&journal);
  const std::shared_ptr<Scene> scene = registry.Create("held");
  SceneOp op;
  op.kind = "AddObject";  // the journal here stores nothing; a model edit only needs to say what it was
  scene->AddObject(Ball("ball"), At(0.1), &op);

  // What a read sees in place: the revision and a body's position.
  struct Seen {
    uint64_t revision = 12345;
    double x = -1;
  };
  auto read_into = [](Seen* seen) {
    return [seen](const SceneModel&, const SceneState& state, uint64_t revision) {
      seen->revision = revision;
      seen->x = state.body_poses[0].position.x();
    };
  };
  Seen seen;
  ASSERT_TRUE(scene->TryRead(read_into(&seen)));
  const SceneView reference = scene->View();
  EXPECT_EQ(seen.revision, reference.revision);
  EXPECT_DOUBLE_EQ(seen.x, reference.state.body_poses[0].position.x());

  journal.Arm();
  auto writer = std::async(std::launch::async, [&] { return scene->SetBodyPoses({{"ball", At(0.2)}}); });
  journal.WaitEntered();
  // The writer waits inside the journal's commit with the writers' lock held: a reader neither waits for it
  // nor sees its edit, which is not stored yet.
  Seen during;
  ASSERT_TRUE(scene->TryRead(read_into(&during)));
  EXPECT_EQ(during.revision, reference.revision);
  EXPECT_DOUBLE_EQ(during.x, 0.1);
  EXPECT_DOUBLE_EQ(scene->View().state.body_poses[0].position.x(), 0.1);
  EXPECT_TRUE(registry.TryGet(scene->id()) != nullptr);  // the registry itself is free
  journal.Release();
  const uint64_t revision = writer.get();

  ASSERT_TRUE(scene->TryRead(read_into(&seen)));
  EXPECT_EQ(seen.revision, revision);
  EXPECT_DOUBLE_EQ(seen.x, 0.2);
  Seen waited;
  scene->Read(read_into(&waited));
  EXPECT_EQ(waited.revision, revision);
}

TEST(SceneTryView, RegistryGivesUpWhileASceneIsCreatedAndNamesUnknownIds) {
  Limits limits;
  SceneRegistry registry(limits);
  HeldJournal journal;
  registry.AttachJournal(&journal);
  const std::shared_ptr<Scene> first = registry.Create("first");
  test_util::ExpectError([&] { registry.TryGet("nope"); }, ErrorCode::kNotFound, {"nope"});

  journal.Arm();
  auto creator = std::async(std::launch::async, [&] { return registry.Create("second"); });
  journal.WaitEntered();
  EXPECT_EQ(registry.TryGet(first->id()), nullptr);
  journal.Release();
  creator.get();
  EXPECT_EQ(registry.TryGet(first->id()), first);
}

}  // namespace
}  // namespace graspsim
