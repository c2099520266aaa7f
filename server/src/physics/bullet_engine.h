// Private to physics/: the Bullet backend of physics/engine.h.
#pragma once

#include <memory>

#include "physics/engine.h"

namespace graspsim {

std::shared_ptr<PhysicsEngine> MakeBulletEngine(std::shared_ptr<const SceneModel> model);

}  // namespace graspsim
