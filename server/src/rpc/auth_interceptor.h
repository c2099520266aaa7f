// The gRPC side of auth: server credentials (TLS, optionally requesting client certificates) and the one
// interceptor that judges every call with auth::Authorizer (auth/auth.h) before it reaches a service. Here in rpc/,
// not auth/, because only the gRPC edge includes gRPC (docs/architecture.md, "Folder map").
//
// gRPC C++ server interceptors cannot end a call themselves, so the interceptor records its refusal and the
// call helpers (rpc/call.h Handle, and the few stream starts that do not go through it) ask RefusedCall first
// and finish the call with that status without running the body. Services never parse tokens or roles.
#pragma once

#include <memory>
#include <optional>
#include <string>

#include <grpcpp/grpcpp.h>
#include <grpcpp/support/server_interceptor.h>

#include "auth/auth.h"

namespace graspsim::rpc {

struct TlsFiles {
  std::string cert, key;  // PEM; both empty = no TLS
  std::string client_ca;  // PEM of the CA that signs gateways' client certificates; empty = none requested
};

// Throws Error(kInvalidArgument) naming the flag when a file cannot be read.
std::shared_ptr<grpc::ServerCredentials> ServerCredentials(const TlsFiles& tls);
std::string ReadPemFile(const std::string& flag, const std::string& path);

struct InterceptorOptions {
  bool tokens = false;              // bearer tokens and roles checked (a token file was given)
  bool gateway_needs_cert = false;  // GatewayService/Connect only with a verified client certificate
};

std::unique_ptr<grpc::experimental::ServerInterceptorFactoryInterface> MakeInterceptorFactory(
    auth::Authorizer* authorizer, const InterceptorOptions& options);

// The refusal the interceptor decided for this call, if any.
std::optional<grpc::Status> RefusedCall(const grpc::ServerContextBase& context);
// The caller of an AuthService call as the interceptor found it (nullopt when tokens are off).
std::optional<auth::Identity> CallerOf(const grpc::ServerContextBase& context);

}  // namespace graspsim::rpc
