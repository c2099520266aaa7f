// SceneService's model edits, translated: a request becomes its edit record (edits/edit_records.h), the typed edit
// API applies and journals it (edits/scene_edits.h), and the result becomes the reply. LegacyEdit reads the ops
// that journals stored before edit records (the serialized requests), so those scenes still open.
#pragma once

#include <string>
#include <vector>

#include "core/limits.h"
#include "edits/edit_codec.h"
#include "graspsim/v1/scene.pb.h"
#include "world/scene.h"

namespace graspsim::rpc {

void AddObjectFromRequest(Scene* scene, const v1::AddObjectRequest& request, const Limits& limits,
                          v1::Body* response);
void AddRobotFromRequest(Scene* scene, const v1::AddRobotRequest& request, const Limits& limits,
                         v1::AddRobotResponse* response);
std::vector<std::string> RemoveBodyFromRequest(Scene* scene, const v1::RemoveBodyRequest& request);
void SetSimulationParamsFromRequest(Scene* scene, const v1::SetSimulationParamsRequest& request,
                                    v1::SimulationParams* response);

// A version-1 journal op (kind and serialized request) as its edit record. Error(kInternal) when it does not parse.
edits::Edit LegacyEdit(const SceneOp& op, const Limits& limits);
// LegacyEdit as the reader the edit API's restore functions take (edits/scene_restore.h).
edits::LegacyEditReader LegacyEditReaderFor(const Limits& limits);

}  // namespace graspsim::rpc
