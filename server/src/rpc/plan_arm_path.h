// GraspService.PlanArmPath(s): request -> motion::PlanArmPathInScene (motion/arm_path_request.h) -> response.
#pragma once

#include <functional>

#include "graspsim/v1/grasp.pb.h"
#include "rpc/scene_overlays.h"
#include "world/scene_registry.h"

namespace graspsim::rpc {

// Throws Error naming the field for bad input; `cancelled` is polled during the search. A planned path's tip
// path goes to `overlays` (may be null) for the viewer.
void PlanArmPath(const v1::PlanArmPathRequest& request, const SceneRegistry& registry,
                 const std::function<bool()>& cancelled, v1::PlanArmPathResponse* response,
                 SceneOverlays* overlays = nullptr);

// Each problem as PlanArmPath, in order; a problem's error becomes its result's status, not the call's.
void PlanArmPaths(const v1::PlanArmPathsRequest& request, const SceneRegistry& registry,
                  const std::function<bool()>& cancelled, v1::PlanArmPathsResponse* response);

}  // namespace graspsim::rpc
