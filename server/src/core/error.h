// Errors that cross the engine's boundary. Validation throws graspsim::Error with a code and a message naming
// the field and the value; the RPC layer maps the code onto a gRPC status. Inside the engine inputs are trusted.
#pragma once

#include <stdexcept>
#include <string>

namespace graspsim {

enum class ErrorCode {
  kInvalidArgument,
  kNotFound,
  kAlreadyExists,
  kFailedPrecondition,
  kResourceExhausted,
  kUnimplemented,
  kInternal,
};

class Error : public std::runtime_error {
 public:
  Error(ErrorCode code, const std::string& message) : std::runtime_error(message), code_(code) {}
  ErrorCode code() const { return code_; }

 private:
  ErrorCode code_;
};

[[noreturn]] inline void ThrowInvalidArgument(const std::string& message) {
  throw Error(ErrorCode::kInvalidArgument, message);
}
[[noreturn]] inline void ThrowNotFound(const std::string& message) { throw Error(ErrorCode::kNotFound, message); }
[[noreturn]] inline void ThrowResourceExhausted(const std::string& message) {
  throw Error(ErrorCode::kResourceExhausted, message);
}

}  // namespace graspsim
