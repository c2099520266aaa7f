// RunWorkCycle's run on a Scene without gRPC (workcycle/scene_work_cycle.h): the frames do not depend on how the
// run is cut into calls (one chunk a call, or many chunks while the wall-time budget lasts); the scene holds the
// cycle's end state, stored once at the end (a fake journal sees the checkpoints), not per chunk; a refused
// request throws before any step; a cycle that fails commits and stores the steps before the error.
#include "workcycle/scene_work_cycle.h"

#include <chrono>
#include <vector>

#include <gtest/gtest.h>

#include "import/robot_import.h"
#include "test_bodies.h"
#include "test_util.h"
#include "world/loaders.h"

namespace graspsim {
namespace {

using test_objects::UniformBox;
using test_util::ExpectError;

Pose At(double x, double y, double z) { return {Vec3(x, y, z), Quat::Identity()}; }

// The built-in cell 1.04 m up over a 0.2 kg 5 cm cube on a support (as tests/cpp/workcycle/work_cycle_test.cpp).
std::shared_ptr<Scene> CellScene() {
  auto scene = std::make_shared<Scene>("cycle", "work cycle", Limits());
  scene->AddObject(UniformBox("support", Vec3(0.2, 0.2, 0.04), 1, BodyMotion::kStatic), At(0, 0, 0.73));
  scene->AddObject(UniformBox("cube", Vec3::Constant(0.05), 0.2), At(0, 0, 0.775));
  scene->AddRobot("cell", "builtin:schunk_pg70_on_z_axis",
                  LoadUrdf(BuiltinModelUrdf("schunk_pg70_on_z_axis"), nullptr, Limits()), At(0, 0, 1.04));
  return scene;
}

WorkCycleRequest Request() {
  WorkCycleRequest request;
  request.gripper_id = "cell";
  request.object_id = "cube";
  request.hold_time = 0.1;
  return request;
}

struct CycleRun {
  std::vector<WorkCycleFrame> frames;
  int calls = 0;
  SceneState end;
  std::vector<double> checkpoints;
};

CycleRun RunToTheEnd(size_t max_frames, std::chrono::nanoseconds wall_time) {
  auto scene = CellScene();
  test_util::CheckpointJournal journal;
  scene->AttachJournal(&journal);
  SimulationCache simulations;
  SceneWorkCycle run(scene, Request(), &simulations);
  CycleRun out;
  while (!run.done() && out.calls < 100000) {
    run.Advance(&out.frames, max_frames, wall_time);
    ++out.calls;
  }
  EXPECT_TRUE(run.done());
  out.end = scene->View().state;
  out.checkpoints = journal.checkpoint_times;
  return out;
}

TEST(SceneWorkCycle, FramesAndTheEndStateDoNotDependOnHowTheRunIsCut) {
  const CycleRun one_chunk = RunToTheEnd(1, std::chrono::nanoseconds(0));      // one 1/60 s chunk a call
  const CycleRun long_calls = RunToTheEnd(64, std::chrono::seconds(10));      // chunks until 64 frames came
  ASSERT_FALSE(one_chunk.frames.empty());
  EXPECT_EQ(one_chunk.frames.front().stage, WorkCycleStage::kApproach);
  EXPECT_EQ(one_chunk.frames.back().stage, WorkCycleStage::kDone);
  EXPECT_GT(one_chunk.calls, long_calls.calls);
  ASSERT_EQ(one_chunk.frames.size(), long_calls.frames.size());
  for (size_t i = 0; i < one_chunk.frames.size(); ++i) {
    ASSERT_EQ(one_chunk.frames[i].time, long_calls.frames[i].time) << i;
    ASSERT_EQ(one_chunk.frames[i].pads[0].intensities, long_calls.frames[i].pads[0].intensities) << i;
  }
  EXPECT_EQ(one_chunk.end.time, long_calls.end.time);
  EXPECT_EQ(one_chunk.end.body_poses[1].position, long_calls.end.body_poses[1].position);
  // Stored at the end, and otherwise at most once a second of wall time: never once per chunk.
  for (const CycleRun* run : {&one_chunk, &long_calls}) {
    ASSERT_FALSE(run->checkpoints.empty());
    EXPECT_EQ(run->checkpoints.back(), run->end.time);
  }
  EXPECT_LT(one_chunk.checkpoints.size(), size_t(one_chunk.calls) / 4);
}

TEST(SceneWorkCycle, ARefusedRequestThrowsBeforeAnyStep) {
  auto scene = CellScene();
  SimulationCache simulations;
  WorkCycleRequest request = Request();
  request.gripper_id = "nope";
  SceneWorkCycle run(scene, request, &simulations);
  const uint64_t revision = scene->revision();
  std::vector<WorkCycleFrame> frames;
  ExpectError([&] { run.Advance(&frames); }, ErrorCode::kNotFound, {"gripper_id: no robot 'nope'"});
  EXPECT_TRUE(frames.empty());
  EXPECT_EQ(run.cycle(), nullptr);
  EXPECT_EQ(scene->revision(), revision);
  EXPECT_EQ(scene->View().state.time, 0);
}

TEST(SceneWorkCycle, AFailedCycleKeepsAndStoresTheStepsBeforeTheError) {
  auto scene = CellScene();
  test_util::CheckpointJournal journal;
  scene->AttachJournal(&journal);
  SimulationCache simulations;
  SceneWorkCycle run(scene, Request(), &simulations);
  std::vector<WorkCycleFrame> frames;
  run.Advance(&frames);  // planned with the cube under the pads …
  scene->SetBodyPoses({{"cube", At(0.5, 0, 0.775)}});  // … which is then taken away
  journal.checkpoint_times.clear();
  ExpectError([&] {
    for (int i = 0; i < 100000 && !run.done(); ++i) run.Advance(&frames);
  }, ErrorCode::kFailedPrecondition, {"without touching 'cube'"});
  EXPECT_EQ(frames.back().stage, WorkCycleStage::kGrasp);
  const double time = scene->View().state.time;
  EXPECT_GT(time, 0);
  EXPECT_GE(time, frames.back().time);  // the scene holds the steps the frames show
  ASSERT_FALSE(journal.checkpoint_times.empty());
  EXPECT_EQ(journal.checkpoint_times.back(), time);
}

}  // namespace
}  // namespace graspsim
