// The scene store (persistence/scene_store.h) and the state codec: every stored kind round-trips bit for bit
// through a closed and reopened database; a transaction that fails before its commit leaves nothing behind; a
// file that is not a database is refused with its path and left as it was.
#include <filesystem>
#include <fstream>
#include <random>
#include <thread>

#include <gtest/gtest.h>

#include "core/error.h"
#include "core/sha256.h"
#include "persistence/scene_store.h"
#include "persistence/state_codec.h"
#include "test_util.h"

namespace graspsim::persistence {
namespace {

namespace fs = std::filesystem;

// A fresh directory under the system's temporary directory, removed at the end of the test.
// Every field set to something other than its default, derived ones included.
SceneState FullState() {
  SceneState s;
  s.time = 1.25;
  s.step = 1250;
  Pose a;
  a.position = Vec3(0.1, -0.2, 0.3);
  a.orientation = Quat(std::sqrt(0.5), 0, std::sqrt(0.5), 0);
  s.body_poses = {a, Pose()};
  s.joint_positions = {0.01, -1.0 / 3.0};
  s.body_velocities = {{Vec3(1, 2, 3), Vec3(-1, -2, -3)}, {}};
  s.joint_velocities = {0.5, -0.25};
  s.sleeping = {true, false};
  s.rest_time = {0.75, 0};
  s.bristles = {{ContactKey{0, 1, 42}, Vec3(1e-6, 2e-6, -3e-6)}, {ContactKey{1, 0, 7}, Vec3(0, 0, 1e-9)}};
  JointActuator actuator;
  actuator.motor.ratio = 123;
  actuator.command = {ActuatorMode::kPosition, 0.02, 1.5};
  actuator.state = {0.3, -0.004};
  actuator.joint_force = 12.5;
  actuator.voltage = -3;
  s.actuators[1] = actuator;
  s.pad_forces = {{Vec3(0, 0, 1), Vec3(0, 0.5, 2)}, {}};
  s.joint_wrenches = {{Vec3(1, 0, 0), Vec3(0, 1, 0)}, {Vec3(0, 0, 9.81), Vec3(0.1, 0.2, 0.3)}};
  s.contacts = {{0, 1, Vec3(0.5, 0.5, 0), Vec3(0, 0, 4.9)}};
  return s;
}

void ExpectSameState(const SceneState& a, const SceneState& b) {
  // The encoding is every field's bytes: equal encodings are equal states, bit for bit.
  EXPECT_EQ(EncodeState(a), EncodeState(b));
  ASSERT_EQ(a.body_poses.size(), b.body_poses.size());
  EXPECT_EQ(a.body_poses[0].orientation.coeffs(), b.body_poses[0].orientation.coeffs());
  EXPECT_EQ(a.joint_positions, b.joint_positions);
  EXPECT_EQ(a.sleeping, b.sleeping);
  ASSERT_EQ(a.actuators.size(), b.actuators.size());
  EXPECT_EQ(a.actuators.begin()->second.command.value, b.actuators.begin()->second.command.value);
  EXPECT_EQ(a.actuators.begin()->second.motor.ratio, b.actuators.begin()->second.motor.ratio);
  EXPECT_EQ(a.bristles.size(), b.bristles.size());
  EXPECT_EQ(a.contacts.size(), b.contacts.size());
}

TEST(StateCodecTest, EveryFieldRoundTrips) {
  const SceneState state = FullState();
  const SceneState back = DecodeState(EncodeState(state), "test");
  ExpectSameState(state, back);
  EXPECT_EQ(back.time, 1.25);
  EXPECT_EQ(back.step, 1250u);
  EXPECT_EQ(back.bristles[0].first, (ContactKey{0, 1, 42}));
  EXPECT_EQ(back.bristles[0].second, Vec3(1e-6, 2e-6, -3e-6));
  EXPECT_EQ(back.actuators.at(1).command.mode, ActuatorMode::kPosition);
  EXPECT_EQ(back.actuators.at(1).state.velocity_error_integral, -0.004);
  EXPECT_EQ(back.pad_forces[0][1], Vec3(0, 0.5, 2));
  EXPECT_EQ(back.joint_wrenches[1][0], Vec3(0, 0, 9.81));
  EXPECT_EQ(back.contacts[0].force, Vec3(0, 0, 4.9));
}

TEST(StateCodecTest, DamagedBytesAreRefusedNotMisread) {
  const std::string bytes = EncodeState(FullState());
  test_util::ExpectError([&] { DecodeState(bytes.substr(0, bytes.size() - 1), "the state of scene-1"); },
                         ErrorCode::kInternal, {"the state of scene-1"});
  test_util::ExpectError([&] { DecodeState(bytes + "x", "s"); }, ErrorCode::kInternal, {"trailing"});
  std::string wrong = bytes;
  wrong[0] ^= 1;
  test_util::ExpectError([&] { DecodeState(wrong, "s"); }, ErrorCode::kInternal, {"not a scene state"});
  // A count far beyond the bytes that follow is refused before anything is allocated.
  std::string huge = bytes;
  huge[4 + 16 + 7] = '\x7f';  // the high byte of body_poses' count
  test_util::ExpectError([&] { DecodeState(huge, "s"); }, ErrorCode::kInternal, {"exceeds the data"});
}

SceneOp Op(const std::string& kind, const std::string& payload) {
  SceneOp op;
  op.kind = kind;
  op.payload = payload;
  return op;
}

SceneOp FileOp(const std::string& path, const std::string& bytes) {
  SceneOp op;
  op.kind = "UploadFile";
  op.path = path;
  op.file = std::make_shared<const std::string>(bytes);
  op.sha256 = Sha256Hex(bytes);
  return op;
}

TEST(SceneStoreTest, EveryStoredKindSurvivesReopening) {
  test_util::TempDir dir("store-test");
  std::string big(3 << 20, '\0');  // a 3 MiB upload with every byte value
  for (size_t i = 0; i < big.size(); ++i) big[i] = static_cast<char>(i * 7919 % 251);
  const SceneState state = FullState();
  {
    SceneStore store(dir.str());
    store.SceneCreated("scene-1", "first", 2);
    store.SceneCreated("scene-2", "second: ünïcödé", 3);
    const SceneOp file = FileOp("meshes/part.stl", big);
    store.SceneChanged("scene-1", &file, SceneState(), 1);
    const SceneOp add = Op("AddObject", std::string("\x0a\x00\xff request bytes", 17));
    store.SceneChanged("scene-1", &add, SceneState(), 2);
    for (const char* kind : {"AddRobot", "RemoveBody", "SetSimulationParams"}) {
      const SceneOp op = Op(kind, std::string(kind) + " bytes");
      store.SceneChanged("scene-1", &op, SceneState(), 3);
    }
    store.SceneChanged("scene-1", nullptr, state, 7);  // a change of state only
  }
  SceneStore reopened(dir.str());
  const StoredScenes stored = reopened.Load();
  EXPECT_EQ(stored.next_id, 3u);
  ASSERT_EQ(stored.scenes.size(), 2u);
  const StoredScene& first = stored.scenes[0];
  EXPECT_EQ(first.id, "scene-1");
  EXPECT_EQ(first.name, "first");
  EXPECT_EQ(stored.scenes[1].name, "second: ünïcödé");
  EXPECT_EQ(first.revision, 7u);
  ExpectSameState(first.state, state);
  ASSERT_EQ(first.ops.size(), 5u);
  EXPECT_EQ(first.ops[0].kind, "UploadFile");
  EXPECT_EQ(first.ops[0].path, "meshes/part.stl");
  ASSERT_TRUE(first.ops[0].file);
  EXPECT_TRUE(*first.ops[0].file == big);
  EXPECT_EQ(first.ops[0].sha256, Sha256Hex(big));
  EXPECT_EQ(first.ops[1].kind, "AddObject");
  EXPECT_EQ(first.ops[1].payload, std::string("\x0a\x00\xff request bytes", 17));
  EXPECT_EQ(first.ops[2].kind, "AddRobot");
  EXPECT_EQ(first.ops[3].kind, "RemoveBody");
  EXPECT_EQ(first.ops[4].payload, "SetSimulationParams bytes");
  EXPECT_TRUE(stored.scenes[1].ops.empty());
  EXPECT_EQ(stored.scenes[1].revision, 0u);
}

TEST(SceneStoreTest, ADeletedSceneStaysDeletedAndItsIdIsNotReused) {
  test_util::TempDir dir("store-test");
  {
    SceneStore store(dir.str());
    store.SceneCreated("scene-1", "a", 2);
    store.SceneCreated("scene-2", "b", 3);
    const SceneOp file = FileOp("f.bin", "bytes");
    store.SceneChanged("scene-2", &file, SceneState(), 1);
    store.SceneDeleted("scene-2");
  }
  const StoredScenes stored = SceneStore(dir.str()).Load();
  ASSERT_EQ(stored.scenes.size(), 1u);
  EXPECT_EQ(stored.scenes[0].id, "scene-1");
  EXPECT_EQ(stored.next_id, 3u);  // scene-2 is never handed out again
  // Writing to a scene that is not stored is an error, not a silent no-op.
  SceneStore store(dir.str());
  test_util::ExpectError([&] { store.SceneChanged("scene-2", nullptr, SceneState(), 2); }, ErrorCode::kInternal,
                         {"scene-2", "not stored"});
}

// Fails every transaction just before its COMMIT, after all of its statements ran.
class FailingStore : public SceneStore {
 public:
  using SceneStore::SceneStore;
  bool fail = false;

 protected:
  void BeforeCommit() override {
    if (fail) throw Error(ErrorCode::kInternal, "injected failure");
  }
};

TEST(SceneStoreTest, ATransactionThatFailsBeforeItsCommitLeavesNothing) {
  test_util::TempDir dir("store-test");
  {
    FailingStore store(dir.str());
    store.SceneCreated("scene-1", "kept", 2);
    const SceneOp add = Op("AddObject", "first");
    store.SceneChanged("scene-1", &add, FullState(), 1);
    store.fail = true;
    const SceneOp file = FileOp("big.bin", std::string(1 << 20, 'x'));
    test_util::ExpectError([&] { store.SceneChanged("scene-1", &file, SceneState(), 2); }, ErrorCode::kInternal,
                           {"injected"});
    test_util::ExpectError([&] { store.SceneCreated("scene-2", "lost", 3); }, ErrorCode::kInternal, {"injected"});
    test_util::ExpectError([&] { store.SceneDeleted("scene-1"); }, ErrorCode::kInternal, {"injected"});
    // The connection is usable after a rollback.
    store.fail = false;
    store.SceneChanged("scene-1", nullptr, FullState(), 3);
  }
  const StoredScenes stored = SceneStore(dir.str()).Load();
  ASSERT_EQ(stored.scenes.size(), 1u);
  EXPECT_EQ(stored.next_id, 2u);
  const StoredScene& scene = stored.scenes[0];
  EXPECT_EQ(scene.revision, 3u);
  ASSERT_EQ(scene.ops.size(), 1u);  // the file of the failed transaction is not there, not even in part
  EXPECT_EQ(scene.ops[0].payload, "first");
  ExpectSameState(scene.state, FullState());
}

TEST(SceneStoreTest, ConcurrentWritesAreCommittedTogetherEachWholeAndInOrder) {
  test_util::TempDir dir("store-test");
  constexpr int kThreads = 6, kWrites = 40;
  {
    SceneStore store(dir.str());
    for (int t = 0; t < kThreads; ++t) store.SceneCreated("scene-" + std::to_string(t + 1), "s", t + 2);
    std::vector<std::thread> threads;
    for (int t = 0; t < kThreads; ++t) {
      threads.emplace_back([&, t] {
        for (int i = 1; i <= kWrites; ++i) {
          const SceneOp op = Op("AddObject", std::to_string(t) + ":" + std::to_string(i));
          SceneState state;
          state.time = i;
          store.SceneChanged("scene-" + std::to_string(t + 1), &op, state, i);
        }
      });
    }
    // Writes that fail in the same batches (no such scene) fail alone.
    threads.emplace_back([&] {
      for (int i = 0; i < kWrites; ++i) {
        const SceneOp op = Op("AddObject", "lost");
        EXPECT_THROW(store.SceneChanged("scene-missing", &op, SceneState(), 1), Error);
      }
    });
    for (auto& thread : threads) thread.join();
  }
  const StoredScenes stored = SceneStore(dir.str()).Load();
  ASSERT_EQ(stored.scenes.size(), size_t{kThreads});
  for (int t = 0; t < kThreads; ++t) {
    const StoredScene& scene = stored.scenes[t];
    EXPECT_EQ(scene.revision, uint64_t{kWrites});
    EXPECT_EQ(scene.state.time, kWrites);
    ASSERT_EQ(scene.ops.size(), size_t{kWrites});
    for (int i = 0; i < kWrites; ++i) EXPECT_EQ(scene.ops[i].payload, std::to_string(t) + ":" + std::to_string(i + 1));
  }
}

TEST(SceneStoreTest, AFileThatIsNotADatabaseIsRefusedNamingItsPathAndKept) {
  test_util::TempDir dir("store-test");
  const fs::path file = dir.path() / "scenes.sqlite";
  const std::string garbage(8192, 'G');
  {
    std::ofstream out(file, std::ios::binary);
    out << garbage;
  }
  test_util::ExpectError([&] { SceneStore store(dir.str()); }, ErrorCode::kFailedPrecondition,
                         {file.string().c_str()});
  std::ifstream in(file, std::ios::binary);
  const std::string after((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  EXPECT_EQ(after, garbage);
}

TEST(SceneStoreTest, ADirectoryThatCannotBeCreatedIsNamed) {
  test_util::TempDir dir("store-test");
  const fs::path blocker = dir.path() / "file";
  std::ofstream(blocker) << "x";
  test_util::ExpectError([&] { SceneStore store((blocker / "sub").string()); }, ErrorCode::kFailedPrecondition,
                         {"sub", "cannot create the directory"});
}

}  // namespace
}  // namespace graspsim::persistence
