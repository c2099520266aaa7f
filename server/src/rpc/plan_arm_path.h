// GraspService.PlanArmPath: request -> motion::PlanPath / PlanPathToPose -> response (translation only).
#pragma once

#include <functional>

#include "graspsim/v1/grasp.pb.h"
#include "world/scene_registry.h"

namespace graspsim::rpc {

// Throws Error naming the field for bad input; `cancelled` is polled during the search.
void PlanArmPath(const v1::PlanArmPathRequest& request, const SceneRegistry& registry,
                 const std::function<bool()>& cancelled, v1::PlanArmPathResponse* response);

}  // namespace graspsim::rpc
