// graspsim.v1.PerceptionService: translation between messages and the perception library (server/src/perception).
// CompleteShape runs on the worker pool and streams its stages (perception_service.cpp); with add_to_scene_id the
// completed mesh becomes a free object of that scene (collision on the closed mesh itself, no convex
// decomposition: the contact finder tests points against closed meshes with Embree). SegmentScene is unary.
#pragma once

#include "core/limits.h"
#include "core/worker_pool.h"
#include "graspsim/v1/perception.grpc.pb.h"
#include "rpc/recording_log.h"
#include "rpc/scene_overlays.h"
#include "world/scene_registry.h"

namespace graspsim::rpc {

class PerceptionServiceImpl final : public v1::PerceptionService::CallbackService {
 public:
  // `overlays` (may be null) receives the symmetry plane of completions added to a scene, for the viewer;
  // `recordings` (may be null) the points such a completion saw, when that scene is being recorded.
  PerceptionServiceImpl(SceneRegistry* registry, WorkerPool* pool, SceneOverlays* overlays = nullptr,
                        RecordingLog* recordings = nullptr)
      : registry_(registry), pool_(pool), overlays_(overlays), recordings_(recordings) {}

  using Context = grpc::CallbackServerContext;
  grpc::ServerWriteReactor<v1::CompleteShapeProgress>* CompleteShape(Context*, const v1::CompleteShapeRequest*) override;
  grpc::ServerUnaryReactor* SegmentScene(Context*, const v1::SegmentSceneRequest*, v1::SegmentSceneResponse*) override;

 private:
  SceneRegistry* registry_;
  WorkerPool* pool_;
  SceneOverlays* overlays_;
  RecordingLog* recordings_;
};

}  // namespace graspsim::rpc
