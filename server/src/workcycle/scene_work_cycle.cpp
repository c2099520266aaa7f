#include "workcycle/scene_work_cycle.h"

#include <optional>

#include "core/error.h"
#include "physics/scene_stepping.h"

namespace graspsim {

void SceneWorkCycle::Advance(std::vector<WorkCycleFrame>* frames, size_t max_frames, std::chrono::nanoseconds wall_time) {
  if (!cycle_) {  // the request against the scene as it is now; errors come before any frame
    const SceneView view = scene_->View();
    cycle_ = std::make_unique<WorkCycle>(view.model, view.state, request_);
  }
  if (cycle_->done()) return;
  const size_t before = frames->size();
  std::optional<Error> failure;
  scene_->Update([&](const std::shared_ptr<const SceneModel>& model, SceneState* state) {
    try {
      // Chunks while they take less than wall_time together (a fast cycle at 100 × real time would otherwise
      // commit and hop threads 6000 times a second) and their frames fit. Held, not borrowed: a DeleteScene
      // meanwhile drops the cache's entry (a cancelled cycle's scene deleted at once freed the engine under
      // this loop: a crash).
      const std::shared_ptr<PhysicsEngine> simulation = simulations_->For(scene_->id(), model);
      const auto until = std::chrono::steady_clock::now() + wall_time;
      for (;;) {
        cycle_->Advance(simulation.get(), state, StepsPerChunk(model->simulation), frames);
        if (cycle_->done() || frames->size() - before >= max_frames || std::chrono::steady_clock::now() >= until) break;
        scene_->PublishDuringUpdate(*state);  // a recording gets every chunk, not only the committed ones
      }
    } catch (const Error& error) {
      failure = error;  // commit the steps done before it: the scene then matches the frames
    }
  }, /*journal=*/false);
  // Stored at the end of the cycle, when it fails, and every kCheckpointInterval of a long cycle, not per chunk
  // (docs/durability.md).
  const auto now = std::chrono::steady_clock::now();
  if (cycle_->done() || failure || now - last_checkpoint_ > kCheckpointInterval) {
    scene_->Checkpoint();
    last_checkpoint_ = now;
  }
  if (failure) throw *failure;
}

}  // namespace graspsim
