// The write reactor every long-lived server stream puts in front of its run object (WatchScene,
// TactileService.Stream and RunWorkCycle, GraspService.PlanGrasps): it forwards gRPC's events to the run, which
// is shared with the scene's hub, alarms and pool jobs and so outlives the reactor; when gRPC is done with the
// reactor, the run is detached (it then ignores late events) and the reactor deletes itself.
#pragma once

#include <memory>
#include <utility>

#include <grpcpp/grpcpp.h>

namespace graspsim::rpc {

// Run: constructed as Run(reactor, args...), with OnWriteDone(bool), OnCancel() and Detach().
template <typename Message, typename Run>
class RunReactor : public grpc::ServerWriteReactor<Message> {
 public:
  template <typename... Args>
  explicit RunReactor(Args&&... args) : run_(std::make_shared<Run>(this, std::forward<Args>(args)...)) {}
  const std::shared_ptr<Run>& run() const { return run_; }

  void OnWriteDone(bool ok) override { run_->OnWriteDone(ok); }
  void OnCancel() override { run_->OnCancel(); }
  void OnDone() override {
    run_->Detach();
    delete this;
  }

 private:
  std::shared_ptr<Run> run_;
};

}  // namespace graspsim::rpc
