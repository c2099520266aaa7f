// A WorkCycle run on a Scene (TactileService.RunWorkCycle's run, without its stream): the cycle advances in
// chunks of 1/60 s of simulated time under the scene's writers' lock, committed together at most every
// `wall_time` so viewers see the cycle and other requests are served, and the state is checkpointed at the end,
// when the cycle fails and every kCheckpointInterval (physics/scene_stepping.h) of a long cycle.
#pragma once

#include <chrono>
#include <memory>
#include <vector>

#include "physics/simulation_cache.h"
#include "workcycle/work_cycle.h"
#include "world/scene.h"

namespace graspsim {

class SceneWorkCycle {
 public:
  SceneWorkCycle(std::shared_ptr<Scene> scene, WorkCycleRequest request, SimulationCache* simulations)
      : scene_(std::move(scene)), request_(std::move(request)), simulations_(simulations) {}

  // Runs the next part of the cycle on the scene and appends its frames. The first call checks the request
  // against the scene as it is then (WorkCycle's errors, before any step). A call runs 1/60 s chunks in one
  // Scene::Update while they took less than `wall_time` together and fewer than `max_frames` frames came (at
  // least one chunk); every chunk but the last is published as a frame to the watchers that want detail. A
  // cycle error (WorkCycle::Advance) is thrown after the steps before it were committed and checkpointed, so
  // the scene matches the frames. Frames do not depend on how the run is split into calls.
  void Advance(std::vector<WorkCycleFrame>* frames, size_t max_frames = 32,
               std::chrono::nanoseconds wall_time = std::chrono::milliseconds(4));

  bool done() const { return cycle_ && cycle_->done(); }
  // Null before the first Advance (or when the request was refused).
  const WorkCycle* cycle() const { return cycle_.get(); }
  const std::shared_ptr<Scene>& scene() const { return scene_; }

 private:
  const std::shared_ptr<Scene> scene_;
  const WorkCycleRequest request_;
  SimulationCache* const simulations_;
  std::unique_ptr<WorkCycle> cycle_;
  std::chrono::steady_clock::time_point last_checkpoint_ = std::chrono::steady_clock::now();
};

}  // namespace graspsim
