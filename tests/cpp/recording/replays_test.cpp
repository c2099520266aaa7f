// Recordings replayed into scenes without gRPC (recording/replays.h), on MCAP files written here with a toy codec
// in place of the API's messages: a recording is read once and again only when its file changed; a replay builds
// a new scene at frame 0 and seeks forward through the edits each frame needs; seeking back past an applied edit,
// past the last frame or in a scene the replay did not make is refused; a recording still being written, without
// states, or with a state that needs edits never recorded is refused; a replay whose edit fails leaves no scene.
#include "recording/replays.h"

#include <filesystem>
#include <random>
#include <sstream>

#include <gtest/gtest.h>

#include "core/error.h"
#include "recording/mcap_writer.h"
#include "test_bodies.h"
#include "test_util.h"

namespace graspsim::recording {
namespace {

namespace fs = std::filesystem;
using test_util::ExpectError;

// The toy recording: an edit is "box <id>" (a 5 cm box added at the origin) or "fail"; a frame is
// "<time> <edits> <z>": every box at height z.
struct Frame {
  double time;
  uint64_t edits;
  double z;
};

void WriteRecording(const std::string& path, const std::vector<std::string>& edits, const std::vector<Frame>& frames,
                    const std::vector<size_t>& edits_before_frame) {
  McapWriter file(path, {});
  const uint16_t schema = file.AddSchema("toy", "text", "");
  const uint16_t edit = file.AddChannel(schema, "/graspsim/edit", "text");
  const uint16_t state = file.AddChannel(schema, "/graspsim/state", "text");
  size_t written = 0;
  for (size_t f = 0; f < frames.size(); ++f) {
    for (; written < edits_before_frame[f]; ++written) file.Write(edit, f, f, edits[written]);
    std::ostringstream text;
    text << frames[f].time << " " << frames[f].edits << " " << frames[f].z;
    file.Write(state, f, f, text.str());
  }
  file.Close();
}

ReplayCodec ToyCodec() {
  ReplayCodec codec;
  codec.edit = [](const std::string&, std::string_view message) {
    SceneOp op;
    op.kind = message.substr(0, 4) == "box " ? "AddObject" : "Broken";
    op.payload = std::string(message);
    return op;
  };
  codec.frame = [](const std::string& name, std::string_view message) {
    std::istringstream in{std::string(message)};
    RecordedFrame frame;
    double z = 0;
    if (!(in >> frame.time >> frame.edits >> z)) {
      throw Error(ErrorCode::kFailedPrecondition, "recording '" + name + "': a state does not parse");
    }
    frame.state = std::to_string(z);
    return frame;
  };
  codec.apply_edit = [](Scene* scene, const SceneOp& op) {
    if (op.kind != "AddObject") throw Error(ErrorCode::kInvalidArgument, "cannot apply '" + op.payload + "'");
    scene->AddObject(test_objects::UniformBox(op.payload.substr(4), Vec3::Constant(0.05), 0.1), Pose());
  };
  return codec;
}

class ReplaysTest : public ::testing::Test {
 protected:
  ReplaysTest() : recorders_(dir_.str()), registry_(Limits()), replays_(&recorders_, &registry_, Codec()) {}

  // decode_state needs the replayed scene's model: every box at height z, the rest as the scene has it.
  ReplayCodec Codec() {
    ReplayCodec codec = ToyCodec();
    codec.decode_state = [this](const std::string& state, const std::string&) {
      SceneState out = decoding_->View().state;
      for (Pose& pose : out.body_poses) pose.position.z() = std::stod(state);
      return out;
    };
    codec.apply_edit = [inner = codec.apply_edit, this](Scene* scene, const SceneOp& op) {
      inner(scene, op);
      decoding_ = scene;
    };
    return codec;
  }
  std::string Path(const std::string& name) const { return dir_.str() + "/" + name; }
  // Three frames: frame 0 needs one box, frames 1 and 2 two.
  void WriteThreeFrames(const std::string& name) {
    WriteRecording(Path(name), {"box a", "box b"}, {{0, 1, 0.1}, {0.5, 2, 0.2}, {1.0, 2, 0.3}}, {1, 2, 2});
  }

  test_util::TempDir dir_{"replays-test", /*create=*/false};
  Recorders recorders_;
  SceneRegistry registry_;
  Replays replays_;
  Scene* decoding_ = nullptr;
};

TEST_F(ReplaysTest, ARecordingIsReadOnceAndAgainWhenItsFileChanged) {
  WriteThreeFrames("run.mcap");
  const auto first = replays_.Load("run.mcap");
  ASSERT_EQ(first->frames.size(), 3u);
  EXPECT_EQ(first->edits.size(), 2u);
  EXPECT_EQ(first->frames[1].time, 0.5);
  EXPECT_EQ(replays_.Load("run.mcap"), first);  // kept
  WriteRecording(Path("run.mcap"), {"box a"}, {{0, 1, 0.1}, {0.25, 1, 0.15}, {0.5, 1, 0.2}, {0.75, 1, 0.25}}, {1, 1, 1, 1});
  const auto again = replays_.Load("run.mcap");
  EXPECT_NE(again, first);
  EXPECT_EQ(again->frames.size(), 4u);
  ExpectError([&] { replays_.Load("nothing.mcap"); }, ErrorCode::kNotFound, {"name: no recording 'nothing.mcap'"});
  ExpectError([&] { replays_.Load("../up.mcap"); }, ErrorCode::kInvalidArgument, {"is not a recording name"});
}

TEST_F(ReplaysTest, AReplayStartsAtFrameZeroAndSeeksForwardThroughTheEdits) {
  WriteThreeFrames("run.mcap");
  const Replays::Started started = replays_.Start("run.mcap", "");
  ASSERT_TRUE(started.scene);
  EXPECT_EQ(started.scene->View().name, "replay of run.mcap");
  SceneView view = started.scene->View();
  ASSERT_EQ(view.model->bodies.size(), 1u);  // the one edit frame 0 needs
  EXPECT_EQ(view.state.body_poses[0].position.z(), 0.1);
  const std::string id = started.scene->id();

  const Replays::Sought at2 = replays_.Seek(id, "run.mcap", 2);
  EXPECT_EQ(at2.time, 1.0);
  view = started.scene->View();
  EXPECT_EQ(at2.revision, view.revision);
  ASSERT_EQ(view.model->bodies.size(), 2u);
  EXPECT_EQ(view.state.body_poses[1].position.z(), 0.3);
  EXPECT_EQ(replays_.Seek(id, "run.mcap", 1).time, 0.5);  // back, but not past an edit: fine
  ExpectError([&] { replays_.Seek(id, "run.mcap", 0); }, ErrorCode::kFailedPrecondition,
              {"frame: 0 comes before edit 2", "replay the recording again"});
  ExpectError([&] { replays_.Seek(id, "run.mcap", 3); }, ErrorCode::kInvalidArgument, {"frame: 3 is past the last frame (2)"});
  WriteThreeFrames("other.mcap");
  ExpectError([&] { replays_.Seek(id, "other.mcap", 0); }, ErrorCode::kFailedPrecondition,
              {"was not made by ReplayRecording of 'other.mcap'"});
  const auto mine = registry_.Create("mine");
  ExpectError([&] { replays_.Seek(mine->id(), "run.mcap", 0); }, ErrorCode::kFailedPrecondition,
              {"scene_id: scene '", "was not made by ReplayRecording of 'run.mcap'"});
}

TEST_F(ReplaysTest, BrokenOrUnfinishedRecordingsAreRefusedAndLeaveNoScene) {
  WriteRecording(Path("stateless.mcap"), {"box a"}, {}, {});
  ExpectError([&] { replays_.Load("stateless.mcap"); }, ErrorCode::kFailedPrecondition,
              {"has no /graspsim/state frames"});
  WriteRecording(Path("ahead.mcap"), {"box a"}, {{0, 3, 0.1}}, {1});
  ExpectError([&] { replays_.Load("ahead.mcap"); }, ErrorCode::kFailedPrecondition,
              {"recording 'ahead.mcap': a state needs edits not recorded"});
  WriteRecording(Path("bad.mcap"), {"box a", "fail"}, {{0, 2, 0.1}}, {2});
  const size_t scenes = registry_.List().size();
  ExpectError([&] { replays_.Start("bad.mcap", "bad"); }, ErrorCode::kFailedPrecondition,
              {"recording 'bad.mcap', edit 2 (Broken): cannot apply 'fail'"});
  EXPECT_EQ(registry_.List().size(), scenes);

  // A recording still being written.
  auto recorded = registry_.Create("recorded");
  RecordingRequest request;
  request.name = "live.mcap";
  recorders_.Start(recorded, request, [](ChannelWriter*) {
    struct Quiet : FrameEncoder {
      void Write(const SceneSnapshot&, FrameReadings&) override {}
      void WritePointCloud(const std::string&, double, const std::vector<Vec3>&) override {}
      void Log(double, int, const std::string&) override {}
    };
    return std::make_unique<Quiet>();
  });
  ExpectError([&] { replays_.Load("live.mcap"); }, ErrorCode::kFailedPrecondition,
              {"name: recording 'live.mcap' of scene '", "is still being written; stop it first"});
}

}  // namespace
}  // namespace graspsim::recording
