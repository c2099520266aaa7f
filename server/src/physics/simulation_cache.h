// One physics engine per scene, rebuilt only when the scene's model changed: building one samples every surface
// and builds the mesh BVHs (graspsim) or compiles the model (MuJoCo), which a step must not repeat.
#pragma once

#include <map>
#include <memory>
#include <mutex>
#include <string>

#include "physics/engine.h"

namespace graspsim {

class SimulationCache {
 public:
  // The scene's simulation for exactly this model. Call under the scene's lock (Scene::Update): a simulation is
  // used by one caller at a time.
  std::shared_ptr<PhysicsEngine> For(const std::string& scene_id, const std::shared_ptr<const SceneModel>& model) {
    std::lock_guard<std::mutex> lock(mutex_);
    std::shared_ptr<PhysicsEngine>& entry = simulations_[scene_id];
    if (!entry || &entry->model() != model.get()) entry = MakePhysicsEngine(model);
    return entry;
  }
  void Forget(const std::string& scene_id) {
    std::lock_guard<std::mutex> lock(mutex_);
    simulations_.erase(scene_id);
  }

 private:
  std::mutex mutex_;
  std::map<std::string, std::shared_ptr<PhysicsEngine>> simulations_;
};

}  // namespace graspsim
