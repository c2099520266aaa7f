// WatchScene as a callback-API server stream: one reactor per viewer, never blocking a gRPC thread.
#pragma once

#include <chrono>
#include <memory>

#include <grpcpp/grpcpp.h>

#include "graspsim/v1/scene.pb.h"
#include "world/scene.h"

namespace graspsim::rpc {

// Streams `scene`'s snapshots, at most one per `min_interval`. The caller validated the request.
// The message WatchScene sends (and recordings store on /graspsim/snapshot).
void ToProto(const SceneSnapshot& snapshot, v1::SceneSnapshot* out);

grpc::ServerWriteReactor<v1::SceneSnapshot>* StartWatch(std::shared_ptr<Scene> scene,
                                                        std::chrono::nanoseconds min_interval);


}  // namespace graspsim::rpc
