// TactileService.RunWorkCycle over a real in-process server: every frame arrives, in order, also to a slow
// reader (flow control, nothing dropped); cancelling stops the run and leaves the scene usable; refused
// requests name the field.
#include <chrono>
#include <memory>
#include <thread>

#include <grpcpp/grpcpp.h>
#include <gtest/gtest.h>

#include "graspsim/v1/scene.grpc.pb.h"
#include "graspsim/v1/tactile.grpc.pb.h"
#include "rpc/server.h"

namespace graspsim::rpc {
namespace {

class WorkCycleRpcTest : public ::testing::Test {
 protected:
  void SetUp() override {
    ServerOptions options;
    options.listen = "127.0.0.1:0";
    options.http_enabled = false;
    options.data_dir = "off";  // scenes in memory: never the user's store, and no test sees another's scenes
    options.worker_threads = 4;
    server_ = std::make_unique<GraspsimServer>(options);
    auto channel = grpc::CreateChannel("127.0.0.1:" + std::to_string(server_->port()),
                                       grpc::InsecureChannelCredentials());
    scenes_ = v1::SceneService::NewStub(channel);
    tactile_ = v1::TactileService::NewStub(channel);
    // The built-in table and cube, the cell's axis base 1.2 m up (as the Python example).
    grpc::ClientContext create;
    v1::CreateSceneRequest create_request;
    v1::Scene scene;
    ASSERT_TRUE(scenes_->CreateScene(&create, create_request, &scene).ok());
    scene_id_ = scene.summary().id();
    auto add_object = [&](const char* name, const char* builtin, double z) {
      grpc::ClientContext context;
      v1::AddObjectRequest request;
      request.set_scene_id(scene_id_);
      request.set_name(name);
      request.set_builtin(builtin);
      request.mutable_pose()->mutable_position()->set_z(z);
      v1::Body body;
      ASSERT_TRUE(scenes_->AddObject(&context, request, &body).ok());
    };
    add_object("table", "table", 0);
    add_object("cube", "cube_5cm", 0.775);
    grpc::ClientContext context;
    v1::AddRobotRequest robot;
    robot.set_scene_id(scene_id_);
    robot.set_name("cell");
    robot.set_builtin("schunk_pg70_on_z_axis");
    robot.mutable_base_pose()->mutable_position()->set_z(1.2);
    v1::AddRobotResponse added;
    ASSERT_TRUE(scenes_->AddRobot(&context, robot, &added).ok());
  }

  v1::RunWorkCycleRequest Request(double frame_rate_hz = 0) const {
    v1::RunWorkCycleRequest request;
    request.set_scene_id(scene_id_);
    request.set_gripper_id("cell");
    request.set_object_id("cube");
    request.set_frame_rate_hz(frame_rate_hz);
    request.set_hold_time(0.1);
    return request;
  }

  // Reads the whole stream, sleeping `pause` after each of the first `slow_frames` frames.
  grpc::Status Run(const v1::RunWorkCycleRequest& request, std::vector<v1::WorkCycleProgress>* frames,
                   std::chrono::milliseconds pause = {}, size_t slow_frames = 0) {
    grpc::ClientContext context;
    auto reader = tactile_->RunWorkCycle(&context, request);
    v1::WorkCycleProgress frame;
    while (reader->Read(&frame)) {
      frames->push_back(frame);
      if (frames->size() <= slow_frames) std::this_thread::sleep_for(pause);
    }
    return reader->Finish();
  }

  std::unique_ptr<GraspsimServer> server_;
  std::unique_ptr<v1::SceneService::Stub> scenes_;
  std::unique_ptr<v1::TactileService::Stub> tactile_;
  std::string scene_id_;
};

TEST_F(WorkCycleRpcTest, StreamsEveryFrameInOrderEndingDone) {
  std::vector<v1::WorkCycleProgress> frames;
  const grpc::Status status = Run(Request(), &frames);  // 50 Hz, the default
  ASSERT_TRUE(status.ok()) << status.error_message();
  ASSERT_GT(frames.size(), 100u);
  EXPECT_EQ(frames.front().stage(), "approach");
  EXPECT_EQ(frames.back().stage(), "done");
  std::vector<std::string> stages;
  for (size_t i = 0; i < frames.size(); ++i) {
    const v1::WorkCycleProgress& frame = frames[i];
    if (i > 0) {
      EXPECT_GT(frame.time(), frames[i - 1].time()) << i;
    }
    if (stages.empty() || stages.back() != frame.stage()) stages.push_back(frame.stage());
    ASSERT_EQ(frame.readings_size(), 3);
    EXPECT_EQ(frame.readings(0).sensor_id(), "cell/pad_left");
    EXPECT_EQ(frame.readings(1).sensor_id(), "cell/pad_right");
    EXPECT_EQ(frame.readings(2).sensor_id(), "cell/gripper");
    EXPECT_EQ(frame.readings(0).tactile().intensities().size(), 84u * 2);
    EXPECT_TRUE(frame.readings(2).has_gripper());
  }
  EXPECT_EQ(stages, (std::vector<std::string>{"approach", "grasp", "lift", "hold", "move_down", "release", "done"}));
  // The scene holds the cycle's end: its time is the last frame's.
  grpc::ClientContext context;
  v1::GetSceneRequest get;
  get.set_scene_id(scene_id_);
  v1::Scene scene;
  ASSERT_TRUE(scenes_->GetScene(&context, get, &scene).ok());
  EXPECT_DOUBLE_EQ(scene.summary().time(), frames.back().time());
}

TEST_F(WorkCycleRpcTest, SlowReaderGetsEveryFrame) {
  // 1 kHz frames, the reader pausing 2 ms after each of the first 300: the simulation waits for it (a frame per
  // step, none dropped), it does not skip ahead.
  std::vector<v1::WorkCycleProgress> frames;
  const grpc::Status status = Run(Request(1000), &frames, std::chrono::milliseconds(2), 300);
  ASSERT_TRUE(status.ok()) << status.error_message();
  for (size_t i = 1; i < frames.size(); ++i) {
    ASSERT_NEAR(frames[i].time() - frames[i - 1].time(), 1e-3, 1e-9) << "frame " << i;
  }
}

TEST_F(WorkCycleRpcTest, CancelStopsTheRunAndLeavesTheSceneUsable) {
  {
    // 1 kHz frames: 4000 of them, far more than the transport buffers, so the cancel meets a running cycle.
    grpc::ClientContext context;
    auto reader = tactile_->RunWorkCycle(&context, Request(1000));
    v1::WorkCycleProgress frame;
    for (int i = 0; i < 5; ++i) ASSERT_TRUE(reader->Read(&frame));
    context.TryCancel();
    while (reader->Read(&frame)) {
    }
    EXPECT_EQ(reader->Finish().error_code(), grpc::StatusCode::CANCELLED);
  }
  grpc::ClientContext context;
  v1::StepSimulationRequest step;
  step.set_scene_id(scene_id_);
  step.set_steps(10);
  v1::StepSimulationResponse stepped;
  ASSERT_TRUE(scenes_->StepSimulation(&context, step, &stepped).ok());
  std::vector<v1::WorkCycleProgress> frames;
  const grpc::Status status = Run(Request(), &frames);  // the next cycle starts from wherever the first stopped
  EXPECT_TRUE(status.ok()) << status.error_message();
  EXPECT_EQ(frames.back().stage(), "done");
}

TEST_F(WorkCycleRpcTest, RefusedRequestsNameTheField) {
  std::vector<v1::WorkCycleProgress> frames;
  v1::RunWorkCycleRequest request = Request();
  request.set_coverage(1.5);
  grpc::Status status = Run(request, &frames);
  EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_EQ(status.error_message(), "coverage: 1.5 is out of range; give a value in (0, 1]");
  request = Request();
  request.set_scene_id("nope");
  status = Run(request, &frames);
  EXPECT_EQ(status.error_code(), grpc::StatusCode::NOT_FOUND);
  request = Request();
  request.set_object_id("table");
  status = Run(request, &frames);
  EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_NE(status.error_message().find("object_id: 'table' is static"), std::string::npos);
  EXPECT_TRUE(frames.empty());
}

}  // namespace
}  // namespace graspsim::rpc
