#include "physics/engine.h"

#include "core/error.h"
#include "physics/bullet_engine.h"
#include "physics/mujoco_engine.h"
#include "physics/simulation.h"

namespace graspsim {

std::string EngineName(PhysicsEngineKind kind) {
  switch (kind) {
    case PhysicsEngineKind::kGraspsim: return "graspsim";
    case PhysicsEngineKind::kMujoco: return "mujoco";
    case PhysicsEngineKind::kBullet: return "bullet";
  }
  return "unknown";
}

void CheckEngineSupports(const SceneModel& model) {
  const PhysicsEngineKind kind = model.simulation.engine;
  if (kind == PhysicsEngineKind::kGraspsim) return;
  // Tactile pads sense through graspsim's foam law at each sensing element; another engine's contacts are not
  // at the elements.
  if (!model.tactile_arrays.empty()) {
    throw Error(ErrorCode::kFailedPrecondition,
                "engine: " + EngineName(kind) + " does not simulate tactile pads (scene has " +
                    std::to_string(model.tactile_arrays.size()) + ", first '" + model.tactile_arrays[0].id + "'" +
                    "); use the graspsim engine");
  }
}

std::shared_ptr<PhysicsEngine> MakePhysicsEngine(std::shared_ptr<const SceneModel> model) {
  CheckEngineSupports(*model);
  if (model->simulation.engine == PhysicsEngineKind::kMujoco) return MakeMujocoEngine(std::move(model));
  if (model->simulation.engine == PhysicsEngineKind::kBullet) return MakeBulletEngine(std::move(model));
  return std::make_shared<Simulation>(std::move(model));
}

}  // namespace graspsim
