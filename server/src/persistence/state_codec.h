// A SceneState as bytes and back, bit for bit: every field, derived ones (contacts, pad forces, joint wrenches)
// included, so a restarted server answers exactly what it answered before it stopped.
#pragma once

#include <string>

#include "world/state.h"

namespace graspsim::persistence {

std::string EncodeState(const SceneState& state);
// Throws Error(kInternal) naming `what` when the bytes are not a state this code wrote.
SceneState DecodeState(const std::string& bytes, const std::string& what);

}  // namespace graspsim::persistence
