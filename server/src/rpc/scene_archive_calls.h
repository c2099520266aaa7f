// SceneService.ExportScene and ImportScene: a scene's archive (persistence/scene_archive.h) streamed out in
// chunks, and a scene rebuilt from the chunks streamed in (edits/scene_restore.h: ArchiveOf, ImportArchive).
#pragma once

#include <grpcpp/grpcpp.h>

#include "core/worker_pool.h"
#include "graspsim/v1/scene.pb.h"
#include "world/scene_registry.h"

namespace graspsim::rpc {

grpc::ServerWriteReactor<v1::SceneArchiveChunk>* StartExport(grpc::CallbackServerContext* context,
                                                             const v1::ExportSceneRequest* request,
                                                             SceneRegistry* registry, WorkerPool* pool);

grpc::ServerReadReactor<v1::SceneArchiveChunk>* StartImport(grpc::CallbackServerContext* context,
                                                            SceneRegistry* registry, WorkerPool* pool,
                                                            v1::Scene* response);

}  // namespace graspsim::rpc
