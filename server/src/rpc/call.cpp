#include "rpc/call.h"

#include "core/log.h"

namespace graspsim::rpc {

grpc::Status ToStatus(const Error& error) {
  switch (error.code()) {
    case ErrorCode::kInvalidArgument: return {grpc::StatusCode::INVALID_ARGUMENT, error.what()};
    case ErrorCode::kNotFound: return {grpc::StatusCode::NOT_FOUND, error.what()};
    case ErrorCode::kAlreadyExists: return {grpc::StatusCode::ALREADY_EXISTS, error.what()};
    case ErrorCode::kFailedPrecondition: return {grpc::StatusCode::FAILED_PRECONDITION, error.what()};
    case ErrorCode::kResourceExhausted: return {grpc::StatusCode::RESOURCE_EXHAUSTED, error.what()};
    case ErrorCode::kUnimplemented: return {grpc::StatusCode::UNIMPLEMENTED, error.what()};
    case ErrorCode::kInternal: break;
  }
  return {grpc::StatusCode::INTERNAL, error.what()};
}

void LogRequest(const char* method, const grpc::ServerContextBase& context, const grpc::Status& status,
                std::chrono::steady_clock::duration elapsed) {
  const bool internal = status.error_code() == grpc::StatusCode::INTERNAL;
  const LogLevel level = internal ? LogLevel::kError : LogLevel::kDebug;
  if (!LogEnabled(level)) return;
  const double ms = std::chrono::duration<double, std::milli>(elapsed).count();
  Log(level, "request", {{"method", method},
                         {"peer", context.peer()},
                         {"code", std::to_string(status.error_code())},
                         {"ms", std::to_string(ms)},
                         {"error", status.error_message()}});
}

}  // namespace graspsim::rpc
