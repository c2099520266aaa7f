// GraspService.PlanGrasps: one pool job resolves the request, finds the set in the store or plans it, and hands
// messages to the reactor. Progress is newest-only (a slow reader sees fewer updates, never a queue); the set
// is the last message. A cancel (the client's, or its deadline passing) stops the planner within one chunk.
#include <chrono>
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
    grasp::StoredGraspSet meta;
    meta.hand = job.hand;
    meta.mesh_hash = grasp::MeshHash(*job.mesh);
    const grasp::GraspSetKey key = grasp::MakeGraspSetKey(job.hand, meta.mesh_hash, job.obstacles, job.candidates,
                                                          job.simulation, job.max_grasps);
    meta.key = key.key;
    meta.params_text = key.params_text;
    if (store && !job.recompute) {
      if (auto stored = store->Find(key.key)) {  // planned before: answer at once
        v1::PlanGraspsProgress last = ProgressMessage(stored->set.candidates, stored->set.candidates);
        ToProto(stored->set, *stored, true, last.mutable_result());
        run->Finish(std::move(last), grpc::Status::OK);
        return;
      }
    }
    if (run->cancelled()) return;
    const grasp::GraspPlanner planner(job.hand, job.mesh, job.obstacles, job.simulation);
    const std::vector<grasp::Candidate> candidates = planner.Candidates(job.candidates);
    // Two threads: the machines have two cores, and other requests keep the pool's other threads.
    const std::optional<grasp::GraspSet> set = planner.Plan(
        candidates, 2, job.max_grasps, [&](size_t done, size_t total) { return run->Progress(ProgressMessage(done, total)); });
    if (!set) return;  // cancelled: the reactor already ends the call
    meta.created_unix =
        std::chrono::duration<double>(std::chrono::system_clock::now().time_since_epoch()).count();
    meta.set = *set;
    if (store) store->Put(meta);
    v1::PlanGraspsProgress last = ProgressMessage(set->candidates, set->candidates);
    ToProto(*set, meta, false, last.mutable_result());
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
