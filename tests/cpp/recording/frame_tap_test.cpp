// FrameTap (recording/frame_tap.h): a scene's published states handed in order, each once, to a consumer on a
// thread of its own. The simulation never waits for it: while the consumer is stuck, publications go on, the queue
// fills to max_queued and later states are dropped and counted; once released, every queued state is consumed in
// publication order with its model and state. Stop drains, finishes once and reports ""; a scene whose hub closes
// (deleted) ends the tap by itself. No wall-clock time is asserted: waits are bounded polls and hang guards.
#include "recording/frame_tap.h"

#include <chrono>
#include <condition_variable>
#include <future>
#include <memory>
#include <mutex>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include <gtest/gtest.h>

#include "core/limits.h"
#include "test_bodies.h"
#include "world/model.h"
#include "world/state.h"

namespace graspsim::recording {
namespace {

// A gate the consumer waits at until the test opens it.
class Gate {
 public:
  void Open() {
    std::lock_guard<std::mutex> lock(mutex_);
    open_ = true;
    opened_.notify_all();
  }
  void Wait() {
    std::unique_lock<std::mutex> lock(mutex_);
    opened_.wait(lock, [&] { return open_; });
  }

 private:
  std::mutex mutex_;
  std::condition_variable opened_;
  bool open_ = false;
};

// One consumed frame as the consumer saw it.
struct Seen {
  uint64_t sequence;
  bool has_model, has_state, has_edits;
  double time, box_z;  // s; m, the first body's height
};

// What a consumer saw; shared with the test, which outlives the tap's thread.
struct Observed {
  mutable std::mutex mutex;
  std::vector<Seen> frames;
  int consume_calls = 0, finish_calls = 0;

  size_t consumed() const {
    std::lock_guard<std::mutex> lock(mutex);
    return frames.size();
  }
  int finished() const {
    std::lock_guard<std::mutex> lock(mutex);
    return finish_calls;
  }
};

class ObservingConsumer : public FrameConsumer {
 public:
  ObservingConsumer(std::shared_ptr<Observed> seen, Gate* gate = nullptr, const char* throw_on_first = nullptr)
      : seen_(std::move(seen)), gate_(gate), throw_on_first_(throw_on_first) {}
  void Consume(const SceneSnapshot& frame) override {
    {
      std::lock_guard<std::mutex> lock(seen_->mutex);
      ++seen_->consume_calls;
      const bool bodies = frame.state && !frame.state->body_poses.empty();
      seen_->frames.push_back({frame.sequence, frame.model != nullptr, frame.state != nullptr, frame.edits != nullptr,
                               frame.state ? frame.state->time : -1, bodies ? frame.state->body_poses[0].position.z() : -1});
    }
    if (gate_) gate_->Wait();
    if (throw_on_first_ && seen_->consume_calls == 1) throw std::runtime_error(throw_on_first_);
  }
  void Finish() override {
    std::lock_guard<std::mutex> lock(seen_->mutex);
    ++seen_->finish_calls;
  }

 private:
  std::shared_ptr<Observed> seen_;
  Gate* gate_;
  const char* throw_on_first_;
};

// Polls `done` until it holds or a generous bound runs out; returns whether it held. A bound, not a timing.
template <typename Pred>
bool Eventually(Pred done) {
  for (int i = 0; i < 20000; ++i) {
    if (done()) return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  return done();
}

constexpr double kEveryFrame = 0;  // FrameTap's interval: no frame is skipped for being close in time

std::shared_ptr<Scene> SceneWithBox() {
  auto scene = std::make_shared<Scene>("scene-1", "frame tap", Limits{});
  scene->AddObject(test_objects::UniformBox("box", Vec3(0.05, 0.05, 0.05), 0.1), Pose{Vec3(0, 0, 2), Quat::Identity()});
  return scene;
}

TEST(FrameTap, AStuckConsumerNeverHoldsUpPublishingAndLateStatesAreDroppedAndCounted) {
  constexpr size_t kMaxQueued = 4;
  constexpr int kUpdates = 50;
  auto scene = SceneWithBox();
  const uint64_t first_sequence = scene->snapshots().Latest()->sequence;
  auto seen = std::make_shared<Observed>();
  Gate gate;
  auto tap = std::make_shared<FrameTap>(scene, std::make_unique<ObservingConsumer>(seen, &gate), kEveryFrame,
                                        kMaxQueued);
  tap->Start();
  EXPECT_TRUE(scene->snapshots().detail_wanted());
  // The consumer is inside its first frame (the scene as it was at Start) and stays there until the gate opens.
  ASSERT_TRUE(Eventually([&] { return seen->consumed() == 1; }));

  // Alternating SetBodyPoses (the box 1 cm lower each time, from 1 m) and Update (time + 1 ms): each publishes.
  auto publishing = std::async(std::launch::async, [&] {
    for (int i = 0; i < kUpdates; ++i) {
      if (i % 2 == 0) {
        scene->SetBodyPoses({{"box", Pose{Vec3(0, 0, 1.0 - 0.01 * i), Quat::Identity()}}});
      } else {
        scene->Update([](const std::shared_ptr<const SceneModel>&, SceneState* state) { state->time += 0.001; });
      }
    }
  });
  // A hang guard, not a timing: publishing that waited for the stuck consumer would never finish.
  const bool published = publishing.wait_for(std::chrono::seconds(120)) == std::future_status::ready;
  if (!published) gate.Open();
  ASSERT_TRUE(published) << "publishing blocked while the consumer was stuck";
  publishing.get();

  EXPECT_EQ(seen->consumed(), 1u) << "the consumer is still stuck in its first frame";
  EXPECT_EQ(tap->frames(), 0u);
  EXPECT_EQ(tap->dropped(), kUpdates - kMaxQueued) << "the queue held " << kMaxQueued << ", the rest were dropped";
  EXPECT_FALSE(tap->finished());

  gate.Open();
  EXPECT_EQ(tap->Stop(), "");
  EXPECT_TRUE(tap->finished());
  EXPECT_FALSE(scene->snapshots().detail_wanted()) << "Stop withdraws the tap's wish for detailed snapshots";
  EXPECT_EQ(tap->frames(), 1 + kMaxQueued);
  EXPECT_EQ(tap->dropped(), kUpdates - kMaxQueued);

  std::lock_guard<std::mutex> lock(seen->mutex);
  ASSERT_EQ(seen->frames.size(), 1 + kMaxQueued);
  EXPECT_EQ(seen->consume_calls, static_cast<int>(1 + kMaxQueued));
  EXPECT_EQ(seen->finish_calls, 1);
  // The first frame, then the first kMaxQueued publications, in order, each with its model and state.
  const double z[] = {2.0, 1.0 - 0.01 * 0, 1.0 - 0.01 * 0, 1.0 - 0.01 * 2, 1.0 - 0.01 * 2};
  const double t[] = {0.0, 0.0, 0.001, 0.001, 0.002};
  for (size_t i = 0; i < seen->frames.size(); ++i) {
    const Seen& frame = seen->frames[i];
    EXPECT_EQ(frame.sequence, first_sequence + i) << "frame " << i;
    EXPECT_TRUE(frame.has_model && frame.has_state && frame.has_edits) << "frame " << i;
    EXPECT_EQ(frame.box_z, z[i]) << "frame " << i;
    EXPECT_EQ(frame.time, t[i]) << "frame " << i;
  }
}

TEST(FrameTap, StopConsumesWhatIsQueuedAndFinishesOnce) {
  auto scene = SceneWithBox();
  auto seen = std::make_shared<Observed>();
  auto tap = std::make_shared<FrameTap>(scene, std::make_unique<ObservingConsumer>(seen));
  tap->Start();
  for (int i = 0; i < 10; ++i) {
    scene->SetBodyPoses({{"box", Pose{Vec3(0, 0, 1.0 + i), Quat::Identity()}}});
  }
  EXPECT_EQ(tap->Stop(), "");
  EXPECT_EQ(tap->frames(), 11u);
  EXPECT_EQ(tap->dropped(), 0u);
  scene->SetBodyPoses({{"box", Pose{Vec3(0, 0, 0.5), Quat::Identity()}}});  // after Stop: not consumed
  tap.reset();  // the destructor of a stopped tap does not finish again
  std::lock_guard<std::mutex> lock(seen->mutex);
  ASSERT_EQ(seen->frames.size(), 11u);
  for (size_t i = 1; i < seen->frames.size(); ++i) {
    EXPECT_EQ(seen->frames[i].sequence, seen->frames[i - 1].sequence + 1);
    EXPECT_EQ(seen->frames[i].box_z, 1.0 + (i - 1));
  }
  EXPECT_EQ(seen->finish_calls, 1);
}

TEST(FrameTap, AClosedHubEndsTheTapByItself) {
  auto scene = SceneWithBox();
  auto seen = std::make_shared<Observed>();
  auto tap = std::make_shared<FrameTap>(scene, std::make_unique<ObservingConsumer>(seen));
  tap->Start();
  scene->SetBodyPoses({{"box", Pose{Vec3(0, 0, 1), Quat::Identity()}}});
  scene->CloseWatchers("scene deleted");
  ASSERT_TRUE(Eventually([&] { return tap->finished(); })) << "the tap did not end when its scene's hub closed";
  EXPECT_EQ(seen->finished(), 1);
  const size_t consumed = seen->consumed();
  EXPECT_EQ(consumed, 2u) << "the first frame and the update queued before the hub closed";
  EXPECT_EQ(tap->frames(), consumed);
  scene->SetBodyPoses({{"box", Pose{Vec3(0, 0, 0.5), Quat::Identity()}}});  // nobody listens any more
  EXPECT_EQ(tap->Stop(), "");
  EXPECT_EQ(seen->consumed(), consumed);
  EXPECT_EQ(seen->finished(), 1);
}

TEST(FrameTap, StartedOnAClosedHubConsumesTheSceneAsItWasAndEnds) {
  auto scene = SceneWithBox();
  scene->CloseWatchers("scene deleted");
  auto seen = std::make_shared<Observed>();
  auto tap = std::make_shared<FrameTap>(scene, std::make_unique<ObservingConsumer>(seen));
  tap->Start();
  ASSERT_TRUE(Eventually([&] { return tap->finished(); }));
  EXPECT_EQ(tap->Stop(), "");
  std::lock_guard<std::mutex> lock(seen->mutex);
  ASSERT_EQ(seen->frames.size(), 1u);
  EXPECT_TRUE(seen->frames[0].has_model && seen->frames[0].has_state);
  EXPECT_EQ(seen->frames[0].box_z, 2.0);
  EXPECT_EQ(seen->finish_calls, 1);
}

TEST(FrameTap, WhatTheConsumerThrowsEndsConsumingAndStopReportsIt) {
  auto scene = SceneWithBox();
  auto seen = std::make_shared<Observed>();
  auto tap = std::make_shared<FrameTap>(scene, std::make_unique<ObservingConsumer>(seen, nullptr, "disk full"));
  tap->Start();
  for (int i = 0; i < 5; ++i) {
    scene->SetBodyPoses({{"box", Pose{Vec3(0, 0, 1.0 + i), Quat::Identity()}}});  // the simulation goes on
  }
  EXPECT_EQ(tap->Stop(), "disk full");
  std::lock_guard<std::mutex> lock(seen->mutex);
  EXPECT_EQ(seen->consume_calls, 1) << "no frame is handed over after the consumer failed";
  EXPECT_EQ(seen->finish_calls, 1);
}

}  // namespace
}  // namespace graspsim::recording
