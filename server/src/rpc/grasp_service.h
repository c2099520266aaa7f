// graspsim.v1.GraspService: translation between messages and the grasp library (server/src/grasp). PlanGrasps is
// a reactor that plans on the worker pool and streams progress (plan_grasps_stream.cpp); grasp sets are kept in
// the SQLite store under --grasp-data-dir. PlanArmPath plans arm paths (rpc/plan_arm_path.cpp, docs/motion.md);
// PickAndPlace plans and executes a pick-and-place on the pool and streams its stages (pick_and_place_stream.cpp).
#pragma once

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "core/worker_pool.h"
#include "graspsim/v1/grasp.grpc.pb.h"
#include "grasp/plan_job.h"
#include "grasp/planner.h"
#include "grasp/store.h"
#include "rpc/scene_overlays.h"
#include "world/scene_registry.h"

namespace graspsim::rpc {

// A PlanGrasps request resolved into the grasp library's inputs (validated).
struct GraspPlanJob : grasp::PlanJob {
  bool recompute = false;
};

class GraspServiceImpl final : public v1::GraspService::CallbackService {
 public:
  // `store` may be null (--grasp-data-dir=off): every request plans.
  // `overlays` (may be null) receives planned arm paths for the viewer.
  GraspServiceImpl(SceneRegistry* registry, WorkerPool* pool, std::shared_ptr<grasp::GraspStore> store,
                   SceneOverlays* overlays = nullptr)
      : registry_(registry), pool_(pool), store_(std::move(store)), overlays_(overlays) {}

  using Context = grpc::CallbackServerContext;
  using Unary = grpc::ServerUnaryReactor;

  grpc::ServerWriteReactor<v1::PlanGraspsProgress>* PlanGrasps(Context*, const v1::PlanGraspsRequest*) override;
  Unary* GetGraspSet(Context*, const v1::GetGraspSetRequest*, v1::GraspSet*) override;
  Unary* EvaluateGrasp(Context*, const v1::EvaluateGraspRequest*, v1::Grasp*) override;
  Unary* PlanArmPath(Context*, const v1::PlanArmPathRequest*, v1::PlanArmPathResponse*) override;
  Unary* PlanArmPaths(Context*, const v1::PlanArmPathsRequest*, v1::PlanArmPathsResponse*) override;
  grpc::ServerWriteReactor<v1::PickAndPlaceProgress>* PickAndPlace(Context*, const v1::PickAndPlaceRequest*) override;

 private:
  SceneRegistry* registry_;
  WorkerPool* pool_;
  std::shared_ptr<grasp::GraspStore> store_;
  SceneOverlays* overlays_;
};

// Translation (grasp_service.cpp), shared with the stream.
GraspPlanJob PlanJobFromProto(const v1::PlanGraspsRequest& request, const SceneRegistry& registry);
void ToProto(const grasp::GraspSet& set, const grasp::StoredGraspSet& meta, bool from_store, v1::GraspSet* out);

// Plans (or finds) the set on the pool and streams it (plan_grasps_stream.cpp).
grpc::ServerWriteReactor<v1::PlanGraspsProgress>* StartPlanGraspsStream(const v1::PlanGraspsRequest& request,
                                                                       const SceneRegistry* registry,
                                                                       std::shared_ptr<grasp::GraspStore> store,
                                                                       WorkerPool* pool,
                                                                       grpc::CallbackServerContext* context);

// Runs a pick-and-place on the pool and streams its stages (pick_and_place_stream.cpp).
grpc::ServerWriteReactor<v1::PickAndPlaceProgress>* StartPickAndPlaceStream(const v1::PickAndPlaceRequest& request,
                                                                           const SceneRegistry* registry,
                                                                           std::shared_ptr<grasp::GraspStore> store,
                                                                           WorkerPool* pool,
                                                                           grpc::CallbackServerContext* context);

}  // namespace graspsim::rpc
