// The edits of a scene's model, from the request messages that ask for them. SceneService's handlers call these,
// each passes its request to the scene's journal (world/scene_journal.h), and on start the stored requests run
// through these same functions again (scene_replay.h): a restored scene is built, and validated, exactly like
// the original.
#pragma once

#include <string>
#include <vector>

#include "core/limits.h"
#include "graspsim/v1/scene.pb.h"
#include "world/scene.h"

namespace graspsim::rpc {

// `response` may be null (replay).
void AddObjectFromRequest(Scene* scene, const v1::AddObjectRequest& request, const Limits& limits,
                          v1::Body* response);
void AddRobotFromRequest(Scene* scene, const v1::AddRobotRequest& request, const Limits& limits,
                         v1::AddRobotResponse* response);
std::vector<std::string> RemoveBodyFromRequest(Scene* scene, const v1::RemoveBodyRequest& request);
void SetSimulationParamsFromRequest(Scene* scene, const v1::SetSimulationParamsRequest& request,
                                    v1::SimulationParams* response);

}  // namespace graspsim::rpc
