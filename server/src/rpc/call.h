// The one place where engine errors become gRPC statuses and where every request is logged.
#pragma once

#include <chrono>
#include <exception>
#include <new>
#include <string>

#include <grpcpp/grpcpp.h>

#include "core/error.h"
#include "core/worker_pool.h"
#include "rpc/auth_interceptor.h"
#include "rpc/failed_call.h"

namespace graspsim::rpc {

grpc::Status ToStatus(const Error& error);

// One line per request: method, peer, status, duration. Debug level for successes and caller errors,
// error level for INTERNAL.
void LogRequest(const char* method, const grpc::ServerContextBase& context, const grpc::Status& status,
                std::chrono::steady_clock::duration elapsed);

// Runs a handler body; an Error becomes its status, anything else INTERNAL (never a crash). A call the auth
// interceptor refused (rpc/auth_interceptor.h) ends with that refusal and the body does not run.
template <typename Body>
grpc::Status Handle(const char* method, const grpc::ServerContextBase& context, Body&& body) {
  const auto start = std::chrono::steady_clock::now();
  grpc::Status status;
  if (auto refused = RefusedCall(context)) return *refused;
  try {
    body();
  } catch (const Error& error) {
    status = ToStatus(error);
  } catch (const std::bad_alloc&) {
    status = grpc::Status(grpc::StatusCode::RESOURCE_EXHAUSTED, std::string(method) + ": out of memory");
  } catch (const std::exception& error) {
    status = grpc::Status(grpc::StatusCode::INTERNAL, std::string(method) + ": " + error.what());
  }
  LogRequest(method, context, status, std::chrono::steady_clock::now() - start);
  return status;
}

// A unary call of the callback API: the body runs on the worker pool (never on gRPC's own threads, which must
// not block), and the call finishes with its status. Request and response stay valid until Finish.
template <typename Body>
grpc::ServerUnaryReactor* RunUnary(grpc::CallbackServerContext* context, const char* method, WorkerPool* pool,
                                   Body&& body) {
  grpc::ServerUnaryReactor* reactor = context->DefaultReactor();
  pool->Post([reactor, context, method, body = std::forward<Body>(body)]() mutable {
    reactor->Finish(Handle(method, *context, body));
  });
  return reactor;
}

// Every server stream starts through one of these two, so none can skip the auth check: a call the auth interceptor
// refused (rpc/auth_interceptor.h) ends with its refusal before any stream exists. With `prepare` (the request's
// checks, run as a handler: an Error becomes the call's status) a rejected request ends likewise; otherwise `start`
// makes the stream.
template <typename Response, typename Start>
grpc::ServerWriteReactor<Response>* StartStream(grpc::CallbackServerContext* context, Start&& start) {
  if (auto refused = RefusedCall(*context)) return new FailedWriter<Response>(*refused);
  return start();
}

template <typename Response, typename Prepare, typename Start>
grpc::ServerWriteReactor<Response>* StartStream(const char* method, grpc::CallbackServerContext* context,
                                                Prepare&& prepare, Start&& start) {
  const grpc::Status status = Handle(method, *context, std::forward<Prepare>(prepare));
  if (!status.ok()) return new FailedWriter<Response>(status);
  return start();
}

// A unary call that is a short read of a scene. `try_body` runs on gRPC's thread and returns false, having
// answered nothing, when it would have to wait for a lock (Scene::TryRead, SceneRegistry::TryGet); then `body`
// runs on the pool as in RunUnary. Saves the two thread switches of the pool's hand-off, which cost a cheap read
// more than its work (tests/bench/run rpc, docs/benchmarks.md).
template <typename TryBody, typename Body>
grpc::ServerUnaryReactor* RunShortRead(grpc::CallbackServerContext* context, const char* method, WorkerPool* pool,
                                       TryBody&& try_body, Body&& body) {
  grpc::ServerUnaryReactor* reactor = context->DefaultReactor();
  bool answered = false;
  const grpc::Status status = Handle(method, *context, [&] { answered = try_body(); });
  if (answered || !status.ok()) {
    reactor->Finish(status);
    return reactor;
  }
  return RunUnary(context, method, pool, std::forward<Body>(body));
}

}  // namespace graspsim::rpc
