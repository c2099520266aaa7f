// The shared state of a long job's server stream (a pool job writing progress, then one last message): progress
// is newest-only (a slow reader sees fewer updates, never a queue), the last message is written after any pending
// progress, then the status. A cancel (the client's, or its deadline passing) marks the run so the job can stop
// at its next progress call. Used behind RunReactor (run_reactor.h) by PerceptionService.CompleteShape and GraspService.PlanGrasps.
#pragma once

#include <atomic>
#include <chrono>
#include <mutex>
#include <optional>
#include <utility>

#include <grpcpp/grpcpp.h>

#include "rpc/call.h"

namespace graspsim::rpc {

template <typename Message>
class ProgressRun {
 public:
  ProgressRun(grpc::ServerWriteReactor<Message>* reactor, grpc::CallbackServerContext* context, const char* method)
      : reactor_(reactor), context_(context), method_(method), start_(std::chrono::steady_clock::now()) {}

  // From the job: replaces any unwritten progress. Returns false once the call is cancelled.
  bool Progress(Message message) {
    std::lock_guard<std::mutex> lock(mutex_);
    if (cancelled_.load()) return false;
    progress_ = std::move(message);
    PumpLocked();
    return true;
  }
  // From the job: the last message (or none) and the status to end with.
  void Finish(std::optional<Message> last, grpc::Status status) {
    std::lock_guard<std::mutex> lock(mutex_);
    if (end_) return;  // cancelled meanwhile
    last_ = std::move(last);
    end_ = std::move(status);
    PumpLocked();
  }
  bool cancelled() const { return cancelled_.load(); }

  // From the reactor.
  void OnWriteDone(bool ok) {
    std::lock_guard<std::mutex> lock(mutex_);
    writing_ = false;
    if (!ok && !end_) EndLocked(grpc::Status(grpc::StatusCode::CANCELLED, "the reader went away"));
    PumpLocked();
  }
  void OnCancel() {
    std::lock_guard<std::mutex> lock(mutex_);
    if (!end_) EndLocked(grpc::Status(grpc::StatusCode::CANCELLED, std::string(method_) + " cancelled"));
    cancelled_ = true;
    PumpLocked();
  }
  void Detach() {
    std::lock_guard<std::mutex> lock(mutex_);
    reactor_ = nullptr;
  }

 private:
  void EndLocked(grpc::Status status) {
    cancelled_ = true;
    progress_.reset();
    last_.reset();
    end_ = std::move(status);
  }
  void PumpLocked() {
    if (!reactor_ || finished_ || writing_) return;
    std::optional<Message>* next = progress_ ? &progress_ : (last_ ? &last_ : nullptr);
    if (next != nullptr) {
      writing_message_ = std::move(**next);
      next->reset();
      writing_ = true;
      reactor_->StartWrite(&writing_message_);
      return;
    }
    if (end_) {
      finished_ = true;
      LogRequest(method_, *context_, *end_, std::chrono::steady_clock::now() - start_);
      reactor_->Finish(*end_);
    }
  }

  std::mutex mutex_;
  grpc::ServerWriteReactor<Message>* reactor_;
  grpc::CallbackServerContext* const context_;
  const char* const method_;
  const std::chrono::steady_clock::time_point start_;
  std::atomic<bool> cancelled_{false};
  std::optional<Message> progress_, last_;
  std::optional<grpc::Status> end_;
  Message writing_message_;
  bool writing_ = false, finished_ = false;
};

// The status of an exception caught by a pool job (as Handle in call.h maps them).
inline grpc::Status StatusOfException(const char* method, const std::exception_ptr& error) {
  try {
    std::rethrow_exception(error);
  } catch (const Error& e) {
    return ToStatus(e);
  } catch (const std::bad_alloc&) {
    return grpc::Status(grpc::StatusCode::RESOURCE_EXHAUSTED, std::string(method) + ": out of memory");
  } catch (const std::exception& e) {
    return grpc::Status(grpc::StatusCode::INTERNAL, std::string(method) + ": " + e.what());
  }
}

}  // namespace graspsim::rpc
