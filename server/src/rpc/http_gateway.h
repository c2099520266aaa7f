// The HTTP/JSON gateway: POST /v1/<Service>/<Method> reaches the same service implementations as gRPC,
// generically. The request JSON becomes the method's protobuf message through protobuf's JSON mapping (the
// method is found by name in the descriptor pool), is sent through an in-process gRPC channel — so every
// interceptor and check applies exactly as over gRPC — and the response comes back as JSON. No code per
// method: a new RPC is reachable over HTTP as soon as it is registered.
//
// Request body: application/json, or application/x-www-form-urlencoded with payload=<json> (GNU Octave's
// webwrite cannot send a raw body). Client-streaming methods take a JSON array of messages.
// Response: the message as JSON (proto field names, defaults included); errors as
// {"code", "status", "message"} with the matching HTTP status. Server streams are Server-Sent Events
// ("event: message" per message, then "event: status"). Query parameters: envelope=1 answers HTTP 200 with
// the status and the response (or "responses" of a stream) in one JSON object, for HTTP stacks that hide
// error bodies; max_messages=N ends a stream after N messages and max_seconds=T after T seconds (both as OK);
// timeout_s=T sets the call's deadline (DEADLINE_EXCEEDED when it passes).
#pragma once

#include <memory>
#include <string>

#include <grpcpp/grpcpp.h>

#include "rpc/scene_overlays.h"

namespace graspsim::rpc {

struct HttpGatewayOptions {
  std::string listen = "127.0.0.1:8080";  // host:port; port 0 = any free port
  int threads = 128;                      // concurrent HTTP requests (each open event stream holds one; a viewer
                                          // page holds two)
  size_t max_body_bytes = 64 << 20;
  std::string viewer_dir;                 // the browser viewer's files (rpc/http_viewer.h); empty = beside the binary
  std::string tls_cert, tls_key;          // PEM files: HTTPS (cpp-httplib's SSLServer); empty = plain HTTP
  const SceneOverlays* overlays = nullptr;  // the viewer's overlays.json (rpc/scene_overlays.h); null = none
};

class HttpGateway {
 public:
  // Binds and starts serving on its own threads; throws Error(kFailedPrecondition) if it cannot bind.
  HttpGateway(std::shared_ptr<grpc::Channel> channel, const HttpGatewayOptions& options);
  ~HttpGateway();

  int port() const;
  void Stop();

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace graspsim::rpc
