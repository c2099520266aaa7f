#include "rpc/unimplemented_services.h"

#include <string>

#include "rpc/call.h"
#include "rpc/failed_call.h"

namespace graspsim::rpc {
grpc::Status NotBuiltYet(const Context& context, const char* method, const char* capability) {
  const grpc::Status status(grpc::StatusCode::UNIMPLEMENTED,
                            std::string("graspsim.v1.") + method + " is declared in API v1 but not implemented yet: " +
                                capability + " is a later issue");
  LogRequest(method, context, status, {});
  return status;
}

Unary* NotBuiltYetUnary(Context* context, const char* method, const char* capability) {
  return FailedUnary(context, NotBuiltYet(*context, method, capability));
}

}  // namespace graspsim::rpc
