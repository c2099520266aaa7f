// The recordings of a server without gRPC (recording/recorders.h, recording_session.h): names are plain file names
// in one directory; one recording per scene, a name used once; a recording's frames reach its encoder and its file,
// Stop and List report the figures (files of earlier runs by name and size); a recording whose scene was deleted
// ends by itself; messages from elsewhere reach the scene's active session only. The protobuf channels are
// replaced by a counting encoder here.
#include "recording/recorders.h"

#include <atomic>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <random>
#include <regex>
#include <thread>

#include <gtest/gtest.h>

#include "test_bodies.h"
#include "test_util.h"
#include "world/scene_registry.h"

namespace graspsim::recording {
namespace {

namespace fs = std::filesystem;
using test_util::ExpectError;

// What the encoders of a test saw.
struct Seen {
  std::atomic<int> frames{0}, logs{0}, appended{0}, clouds{0};
};

// Writes one message per frame on "/frame", so the file's figures move with the frames.
class CountingEncoder : public FrameEncoder {
 public:
  CountingEncoder(ChannelWriter* file, Seen* seen) : file_(file), seen_(seen) {
    channel_ = file_->AddChannel({"/frame", "text", "frame", "", ""});
  }
  void Write(const SceneSnapshot& frame, FrameReadings&) override {
    ++seen_->frames;
    file_->Write(channel_, static_cast<uint64_t>(frame.state->time * 1e9), "frame");
  }
  void WritePointCloud(const std::string&, double, const std::vector<Vec3>&) override { ++seen_->clouds; }
  void Log(double, int, const std::string&) override { ++seen_->logs; }
  void Appended() { ++seen_->appended; }

 private:
  ChannelWriter* file_;
  Seen* seen_;
  uint32_t channel_ = 0;
};

FrameEncoderFactory Counting(Seen* seen) {
  return [seen](ChannelWriter* file) { return std::make_unique<CountingEncoder>(file, seen); };
}

std::shared_ptr<Scene> BoxScene(SceneRegistry* registry, const std::string& name = "recorded") {
  auto scene = registry->Create(name);
  scene->AddObject(test_objects::UniformBox("box", Vec3::Constant(0.05), 0.1), {Vec3(0, 0, 0.5), Quat::Identity()});
  return scene;
}

// Moves the box so that the scene publishes a new state, `n` times, 0.1 s of simulated time apart.
void Publish(Scene* scene, int n) {
  for (int i = 0; i < n; ++i) {
    scene->Update([](const std::shared_ptr<const SceneModel>&, SceneState* state) {
      state->time += 0.1;
      state->body_poses[0].position.x() += 0.01;
    });
  }
}

template <typename Condition>
bool Eventually(Condition done) {
  for (int i = 0; i < 500 && !done(); ++i) std::this_thread::sleep_for(std::chrono::milliseconds(10));
  return done();
}

TEST(Recorders, NamesArePlainFilesOfTheDirectoryAndOffMeansOff) {
  test_util::TempDir dir("recorders-test", /*create=*/false);
  Recorders recorders(dir.str());
  EXPECT_TRUE(fs::is_directory(dir.str()));
  EXPECT_EQ(recorders.PathOf("name", "run-1.mcap"), dir.str() + "/run-1.mcap");
  for (const char* bad : {"../up.mcap", "sub/dir.mcap", ".hidden.mcap", "run.txt", ".mcap", "a b.mcap"}) {
    ExpectError([&] { recorders.PathOf("name", bad); }, ErrorCode::kInvalidArgument, {"name: '", "is not a recording name"});
  }
  Recorders off("");
  SceneRegistry registry{Limits()};
  Seen seen;
  ExpectError([&] { off.Start(BoxScene(&registry), {}, Counting(&seen)); }, ErrorCode::kFailedPrecondition,
              {"recordings are off"});
  EXPECT_TRUE(off.List().empty());
}

TEST(Recorders, ARecordingWritesItsFramesAndReportsThem) {
  test_util::TempDir dir("recorders-test", /*create=*/false);
  Recorders recorders(dir.str());
  SceneRegistry registry{Limits()};
  auto scene = BoxScene(&registry);
  Seen seen;
  RecordingRequest request;
  request.name = "run.mcap";
  request.rate_hz = 1000;
  const RecordingInfo started = recorders.Start(scene, request, Counting(&seen));
  EXPECT_TRUE(started.active);
  EXPECT_EQ(started.scene_id, scene->id());
  EXPECT_EQ(started.path, dir.str() + "/run.mcap");
  EXPECT_EQ(started.ros2_path, dir.str() + "/run.ros2");
  EXPECT_TRUE(fs::exists(started.path));
  EXPECT_TRUE(fs::is_directory(started.ros2_path));
  // One recording per scene, and a name once.
  ExpectError([&] { recorders.Start(scene, request, Counting(&seen)); }, ErrorCode::kAlreadyExists,
              {"scene_id: scene '" , "is already being recorded to 'run.mcap'"});
  ExpectError([&] { recorders.Start(BoxScene(&registry, "other"), request, Counting(&seen)); },
              ErrorCode::kAlreadyExists, {"name: a recording 'run.mcap' exists"});
  Publish(scene.get(), 5);
  ASSERT_TRUE(Eventually([&] { return seen.frames >= 6; }));  // the state at the start, then each one published
  const RecordingInfo stopped = recorders.Stop(scene->id());
  EXPECT_FALSE(stopped.active);
  EXPECT_EQ(stopped.frames, 6u);
  EXPECT_EQ(stopped.dropped_frames, 0u);
  EXPECT_EQ(stopped.messages, 6u);  // the counting encoder's, one a frame
  EXPECT_EQ(stopped.start_time, 0);
  EXPECT_NEAR(stopped.end_time, 0.5, 1e-12);
  EXPECT_EQ(stopped.bytes, fs::file_size(stopped.path));
  EXPECT_EQ(seen.logs, 2);  // started, stopped
  ExpectError([&] { recorders.Stop(scene->id()); }, ErrorCode::kNotFound, {"is not being recorded"});

  // List: this server's recordings with their figures, older files by name and size.
  std::ofstream(dir.str() + "/older.mcap") << "12345";
  const std::vector<RecordingInfo> listed = recorders.List();
  ASSERT_EQ(listed.size(), 2u);
  EXPECT_EQ(listed[0].name, "older.mcap");
  EXPECT_EQ(listed[0].bytes, 5u);
  EXPECT_EQ(listed[0].frames, 0u);
  EXPECT_EQ(listed[1].name, "run.mcap");
  EXPECT_EQ(listed[1].frames, 6u);
  EXPECT_EQ(listed[1].ros2_path, dir.str() + "/run.ros2");
}

TEST(Recorders, RequestsAreCheckedAgainstTheScene) {
  test_util::TempDir dir("recorders-test", /*create=*/false);
  Recorders recorders(dir.str());
  SceneRegistry registry{Limits()};
  auto scene = BoxScene(&registry);
  Seen seen;
  RecordingRequest request;
  request.rate_hz = 1001;
  ExpectError([&] { recorders.Start(scene, request, Counting(&seen)); }, ErrorCode::kInvalidArgument,
              {"rate_hz: 1001", "outside (0, 1000]"});
  request.rate_hz = 0;
  request.force_torque_joints = {"nope"};
  ExpectError([&] { recorders.Start(scene, request, Counting(&seen)); }, ErrorCode::kNotFound,
              {"force_torque_joints: no joint 'nope' in the scene"});
  request.name = "../escape.mcap";
  request.force_torque_joints.clear();
  ExpectError([&] { recorders.Start(scene, request, Counting(&seen)); }, ErrorCode::kInvalidArgument, {"name: '../escape.mcap'"});
  EXPECT_TRUE(recorders.List().empty());
  EXPECT_TRUE(fs::is_empty(dir.str()));
}

TEST(Recorders, AutomaticRecordingsAreNamedByTheSceneAndEndWithIt) {
  test_util::TempDir dir("recorders-test", /*create=*/false);
  Recorders recorders(dir.str());
  SceneRegistry registry{Limits()};
  auto scene = BoxScene(&registry);
  Seen seen;
  recorders.StartAutomatically(scene, Counting(&seen));
  recorders.StartAutomatically(scene, Counting(&seen));  // already recorded: logged, not thrown
  std::vector<RecordingInfo> listed = recorders.List();
  ASSERT_EQ(listed.size(), 1u);
  EXPECT_TRUE(listed[0].active);
  EXPECT_TRUE(std::regex_match(listed[0].name, std::regex(scene->id() + "-\\d{8}T\\d{6}Z\\.mcap"))) << listed[0].name;
  EXPECT_EQ(recorders.ActiveSceneOf(listed[0].name), scene->id());
  // Messages from elsewhere reach the active session of that scene only.
  EXPECT_TRUE(recorders.WithSession(scene->id(), [](RecordingSession& session) {
    session.Append([](FrameEncoder& encoder, double) { static_cast<CountingEncoder&>(encoder).Appended(); });
    session.AppendPointCloud("/seen", {Vec3::Zero()});
  }));
  EXPECT_FALSE(recorders.WithSession("no-such-scene", [](RecordingSession&) { ADD_FAILURE(); }));
  EXPECT_EQ(seen.appended, 1);
  EXPECT_EQ(seen.clouds, 1);
  // The scene deleted: its recording ends by itself and is reported finished.
  registry.Delete(scene->id());
  ASSERT_TRUE(Eventually([&] {
    listed = recorders.List();
    return listed.size() == 1 && !listed[0].active;
  }));
  EXPECT_EQ(recorders.ActiveSceneOf(listed[0].name), "");
  EXPECT_GE(listed[0].frames, 1u);
  ExpectError([&] { recorders.Stop(scene->id()); }, ErrorCode::kNotFound, {"is not being recorded"});
}

}  // namespace
}  // namespace graspsim::recording
