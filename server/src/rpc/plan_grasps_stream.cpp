// GraspService.PlanGrasps: one pool job resolves the request, finds the set in the store or plans it, and hands
// messages to the reactor. Progress is newest-only (a slow reader sees fewer updates, never a queue); the set
// is the last message. A cancel (the client's, or its deadline passing) stops the planner within one chunk.
#include <memory>
#include <optional>

#include "core/error.h"
#include "rpc/call.h"
#include "rpc/failed_call.h"
#include "rpc/grasp_service.h"
#include "rpc/progress_run.h"
#include "rpc/run_reactor.h"

namespace graspsim::rpc {
namespace {

constexpr char kMethod[] = "GraspService/PlanGrasps";


// Shared by the reactor and the pool job; the job may outlive the reactor and then only finds it gone.
using PlanRun = ProgressRun<v1::PlanGraspsProgress>;

v1::PlanGraspsProgress ProgressMessage(size_t done, size_t total) {
  v1::PlanGraspsProgress message;
  message.set_fraction(total > 0 ? static_cast<double>(done) / total : 1.0);
  message.set_candidates_done(done);
  message.set_candidates_total(total);
  return message;
}

void RunPlan(const v1::PlanGraspsRequest& request, const SceneRegistry* registry,
             const std::shared_ptr<grasp::GraspStore>& store, const std::shared_ptr<PlanRun>& run) {
  try {
    const GraspPlanJob job = PlanJobFromProto(request, *registry);
    bool from_store = false;  // planned before: answered at once
    const std::optional<grasp::StoredGraspSet> entry = grasp::FindOrPlan(
        job, store.get(), job.recompute,
        [&](size_t done, size_t total) { return run->Progress(ProgressMessage(done, total)); }, &from_store);
    if (!entry) return;  // cancelled: the reactor already ends the call
    v1::PlanGraspsProgress last = ProgressMessage(entry->set.candidates, entry->set.candidates);
    ToProto(entry->set, *entry, from_store, last.mutable_result());
    run->Finish(std::move(last), grpc::Status::OK);
  } catch (...) {
    run->Finish(std::nullopt, StatusOfException(kMethod, std::current_exception()));
  }
}

}  // namespace

grpc::ServerWriteReactor<v1::PlanGraspsProgress>* StartPlanGraspsStream(const v1::PlanGraspsRequest& request,
                                                                       const SceneRegistry* registry,
                                                                       std::shared_ptr<grasp::GraspStore> store,
                                                                       WorkerPool* pool,
                                                                       grpc::CallbackServerContext* context) {
  auto* reactor = new RunReactor<v1::PlanGraspsProgress, PlanRun>(context, kMethod);
  pool->Post([request, registry, store = std::move(store), run = reactor->run()] { RunPlan(request, registry, store, run); });
  return reactor;
}

}  // namespace graspsim::rpc
