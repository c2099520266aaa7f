// The live Foxglove endpoint (--foxglove-listen): a client connecting to ws://host:port/<scene id> gets that
// scene's channels, the same protobuf channels a recording holds (recording_channels.h), fed from the scene's
// published states by a frame tap of its own. Only channels the client subscribed to are encoded.
#pragma once

#include <memory>
#include <string>

#include "live/foxglove_server.h"
#include "world/scene_registry.h"

namespace graspsim::rpc {

// Throws what live::FoxgloveServer throws when `listen` cannot be bound.
std::unique_ptr<live::FoxgloveServer> StartFoxgloveLive(const std::string& listen, SceneRegistry* registry);

}  // namespace graspsim::rpc
