#include "physics/engine.h"

#include "core/error.h"
#include "core/format.h"
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

void CheckEngineSupports(const SceneModel& model, PhysicsEngineKind kind) {
  if (kind == PhysicsEngineKind::kGraspsim) return;
  // Pads are a foam box on these engines (physics/pad_readout.h): a curved fingertip is not a box.
  for (const TactileArraySpec& pad : model.tactile_arrays) {
    if (pad.bend_radius_x > 0 || pad.bend_radius_y > 0) {
      throw Error(ErrorCode::kFailedPrecondition,
                  "engine: " + EngineName(kind) + " does not simulate curved tactile pads (pad '" + pad.id +
                      "' has bend_radius " + FormatNumber(pad.bend_radius_x) + " " + FormatNumber(pad.bend_radius_y) +
                      " m); use the graspsim engine or a flat pad");
    }
  }
}

void PrepareStateWithoutExtras(const SceneModel& model, SceneState* state) {
  state->body_velocities.resize(model.bodies.size());
  state->joint_velocities.resize(model.joints.size(), 0);
  state->sleeping.assign(model.bodies.size(), false);
  state->rest_time.resize(model.bodies.size(), 0);
  state->joint_wrenches.resize(model.joints.size(), {Vec3::Zero(), Vec3::Zero()});
  state->pad_forces.clear();
}

std::shared_ptr<PhysicsEngine> MakePhysicsEngine(std::shared_ptr<const SceneModel> model) {
  CheckEngineSupports(*model, model->simulation.engine);
  if (model->simulation.engine == PhysicsEngineKind::kMujoco) return MakeMujocoEngine(std::move(model));
  if (model->simulation.engine == PhysicsEngineKind::kBullet) return MakeBulletEngine(std::move(model));
  return std::make_shared<Simulation>(std::move(model));
}

}  // namespace graspsim
