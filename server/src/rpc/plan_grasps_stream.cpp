// GraspService.PlanGrasps: one pool job resolves the request, finds the set in the store or plans it, and hands
// messages to the reactor. Progress is newest-only (a slow reader sees fewer updates, never a queue); the set
// is the last message. A cancel (the client's, or its deadline passing) stops the planner within one chunk.
#include <chrono>
#include <memory>
#include <mutex>
#include <optional>

#include "core/error.h"
#include "rpc/call.h"
#include "rpc/failed_call.h"
#include "rpc/grasp_service.h"
#include "rpc/run_reactor.h"

namespace graspsim::rpc {
namespace {

constexpr char kMethod[] = "GraspService/PlanGrasps";


// Shared by the reactor and the pool job; the job may outlive the reactor and then only finds it gone.
class PlanRun {
 public:
  PlanRun(grpc::ServerWriteReactor<v1::PlanGraspsProgress>* reactor, grpc::CallbackServerContext* context)
      : reactor_(reactor), context_(context), start_(std::chrono::steady_clock::now()) {}

  // From the job: newest-only progress. Returns false once the call is cancelled.
  bool Progress(size_t done, size_t total);
  // From the job: the last message (or none) and the status to end with.
  void Finish(std::optional<v1::PlanGraspsProgress> last, grpc::Status status);
  void OnWriteDone(bool ok);
  void OnCancel();
  void Detach() {
    std::lock_guard<std::mutex> lock(mutex_);
    reactor_ = nullptr;
  }
  bool cancelled() const { return cancelled_.load(); }

 private:
  void PumpLocked();

  std::mutex mutex_;
  grpc::ServerWriteReactor<v1::PlanGraspsProgress>* reactor_;
  grpc::CallbackServerContext* const context_;
  const std::chrono::steady_clock::time_point start_;
  std::atomic<bool> cancelled_{false};
  std::optional<v1::PlanGraspsProgress> progress_, last_;
  std::optional<grpc::Status> end_;
  v1::PlanGraspsProgress writing_message_;
  bool writing_ = false, finished_ = false;
};

bool PlanRun::Progress(size_t done, size_t total) {
  std::lock_guard<std::mutex> lock(mutex_);
  if (cancelled_.load()) return false;
  v1::PlanGraspsProgress message;
  message.set_fraction(total > 0 ? static_cast<double>(done) / total : 1.0);
  message.set_candidates_done(done);
  message.set_candidates_total(total);
  progress_ = std::move(message);
  PumpLocked();
  return true;
}

void PlanRun::Finish(std::optional<v1::PlanGraspsProgress> last, grpc::Status status) {
  std::lock_guard<std::mutex> lock(mutex_);
  if (end_) return;  // cancelled meanwhile
  last_ = std::move(last);
  end_ = std::move(status);
  PumpLocked();
}

void PlanRun::OnWriteDone(bool ok) {
  std::lock_guard<std::mutex> lock(mutex_);
  writing_ = false;
  if (!ok && !end_) {
    cancelled_ = true;
    progress_.reset();
    last_.reset();
    end_ = grpc::Status(grpc::StatusCode::CANCELLED, "the reader went away");
  }
  PumpLocked();
}

void PlanRun::OnCancel() {
  std::lock_guard<std::mutex> lock(mutex_);
  cancelled_ = true;
  progress_.reset();
  last_.reset();
  if (!end_) end_ = grpc::Status(grpc::StatusCode::CANCELLED, "grasp planning cancelled");
  PumpLocked();
}

void PlanRun::PumpLocked() {
  if (!reactor_ || finished_ || writing_) return;
  std::optional<v1::PlanGraspsProgress>* next = last_ ? &last_ : (progress_ ? &progress_ : nullptr);
  if (last_ && progress_) next = &progress_;  // progress first, the set last
  if (next != nullptr) {
    writing_message_ = std::move(**next);
    next->reset();
    writing_ = true;
    reactor_->StartWrite(&writing_message_);
    return;
  }
  if (end_) {
    finished_ = true;
    LogRequest(kMethod, *context_, *end_, std::chrono::steady_clock::now() - start_);
    reactor_->Finish(*end_);
  }
}

grpc::Status StatusOf(const std::exception_ptr& error) {
  try {
    std::rethrow_exception(error);
  } catch (const Error& e) {
    return ToStatus(e);
  } catch (const std::bad_alloc&) {
    return grpc::Status(grpc::StatusCode::RESOURCE_EXHAUSTED, std::string(kMethod) + ": out of memory");
  } catch (const std::exception& e) {
    return grpc::Status(grpc::StatusCode::INTERNAL, std::string(kMethod) + ": " + e.what());
  }
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
        v1::PlanGraspsProgress last;
        last.set_fraction(1);
        last.set_candidates_done(stored->set.candidates);
        last.set_candidates_total(stored->set.candidates);
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
        candidates, 2, job.max_grasps, [&](size_t done, size_t total) { return run->Progress(done, total); });
    if (!set) return;  // cancelled: the reactor already ends the call
    meta.created_unix =
        std::chrono::duration<double>(std::chrono::system_clock::now().time_since_epoch()).count();
    meta.set = *set;
    if (store) store->Put(meta);
    v1::PlanGraspsProgress last;
    last.set_fraction(1);
    last.set_candidates_done(set->candidates);
    last.set_candidates_total(set->candidates);
    ToProto(*set, meta, false, last.mutable_result());
    run->Finish(std::move(last), grpc::Status::OK);
  } catch (...) {
    run->Finish(std::nullopt, StatusOf(std::current_exception()));
  }
}

}  // namespace

grpc::ServerWriteReactor<v1::PlanGraspsProgress>* StartPlanGraspsStream(const v1::PlanGraspsRequest& request,
                                                                       const SceneRegistry* registry,
                                                                       std::shared_ptr<grasp::GraspStore> store,
                                                                       WorkerPool* pool,
                                                                       grpc::CallbackServerContext* context) {
  auto* reactor = new RunReactor<v1::PlanGraspsProgress, PlanRun>(context);
  pool->Post([request, registry, store = std::move(store), run = reactor->run()] { RunPlan(request, registry, store, run); });
  return reactor;
}

}  // namespace graspsim::rpc
