// Calls of the callback API that end at once with a status: a rejected stream request, or a method that is not
// built yet. Each reactor deletes itself when gRPC is done with it.
#pragma once

#include <grpcpp/grpcpp.h>

namespace graspsim::rpc {

template <typename Response>
class FailedWriter : public grpc::ServerWriteReactor<Response> {
 public:
  explicit FailedWriter(const grpc::Status& status) { this->Finish(status); }
  void OnDone() override { delete this; }
};

template <typename Request, typename Response>
class FailedBidi : public grpc::ServerBidiReactor<Request, Response> {
 public:
  explicit FailedBidi(const grpc::Status& status) { this->Finish(status); }
  void OnDone() override { delete this; }
};

inline grpc::ServerUnaryReactor* FailedUnary(grpc::CallbackServerContext* context, const grpc::Status& status) {
  grpc::ServerUnaryReactor* reactor = context->DefaultReactor();
  reactor->Finish(status);
  return reactor;
}

}  // namespace graspsim::rpc
