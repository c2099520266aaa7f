// The services of API v1 whose capabilities later issues build. Each method answers UNIMPLEMENTED with a
// message saying which issue brings it, never a fake result. Replace a class here when its issue lands.
#pragma once

#include <grpcpp/grpcpp.h>

#include "rpc/failed_call.h"

namespace graspsim::rpc {

using Context = grpc::CallbackServerContext;
using Unary = grpc::ServerUnaryReactor;
template <typename Response>
using Writer = grpc::ServerWriteReactor<Response>;

// UNIMPLEMENTED naming the method and the later issue's capability (also for the motion-planning methods that
// GraspService declares).
constexpr char kMotionPlanning[] = "arm motion planning and pick-and-place";
grpc::Status NotBuiltYet(const Context& context, const char* method, const char* capability);
Unary* NotBuiltYetUnary(Context* context, const char* method, const char* capability);
template <typename Response>
Writer<Response>* NotBuiltYetStream(Context* context, const char* method, const char* capability) {
  return new FailedWriter<Response>(NotBuiltYet(*context, method, capability));
}

}  // namespace graspsim::rpc
