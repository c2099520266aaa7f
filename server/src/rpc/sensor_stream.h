// TactileService.Stream as a callback-API server stream: one reactor per reader, never blocking a gRPC thread.
#pragma once

#include <chrono>
#include <memory>
#include <string>
#include <vector>

#include <grpcpp/grpcpp.h>

#include "core/worker_pool.h"
#include "graspsim/v1/tactile.pb.h"
#include "world/scene.h"

namespace graspsim::rpc {

// Streams one reading per sensor of `sensor_ids` each time the scene has changed, at most once per
// `min_interval`, always of the newest state: a slow reader skips states, nothing queues. The first readings go
// at once. Ids are checked against the scene first (on `pool`); a bad one ends the stream with its error before
// anything is written. Ends with UNAVAILABLE when the scene is deleted or the server stops, NOT_FOUND when a
// sensor's robot is removed, CANCELLED when the reader cancels. The caller validated the request's shape.
grpc::ServerWriteReactor<v1::SensorReading>* StartSensorStream(std::shared_ptr<Scene> scene,
                                                               std::vector<std::string> sensor_ids,
                                                               std::chrono::nanoseconds min_interval, WorkerPool* pool,
                                                               grpc::CallbackServerContext* context);

}  // namespace graspsim::rpc
