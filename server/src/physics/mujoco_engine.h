// Private to physics/: the MuJoCo backend of physics/engine.h.
#pragma once

#include <memory>

#include "physics/engine.h"

namespace graspsim {

std::shared_ptr<PhysicsEngine> MakeMujocoEngine(std::shared_ptr<const SceneModel> model);

}  // namespace graspsim
