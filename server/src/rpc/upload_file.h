// SceneService.UploadFile as a callback-API read reactor: chunks are appended as they arrive (header checked on
// the first), and the whole file is checked (size, SHA-256) and stored on the worker pool.
#pragma once

#include <grpcpp/grpcpp.h>

#include "core/worker_pool.h"
#include "graspsim/v1/scene.pb.h"
#include "world/scene_registry.h"

namespace graspsim::rpc {

grpc::ServerReadReactor<v1::UploadFileChunk>* StartUpload(grpc::CallbackServerContext* context,
                                                          SceneRegistry* registry, WorkerPool* pool,
                                                          v1::FileInfo* response);

}  // namespace graspsim::rpc
