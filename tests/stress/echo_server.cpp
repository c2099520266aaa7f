// graspsim_echo_server: a bare gRPC echo service for tests/bench/rpc.py. Built like graspsim-server's gRPC port
// (callback API, the same builder options, no TLS, no interceptor) but answering inline: what gRPC itself costs
// per call on this machine, so that the scene calls' throughput can be read as a fraction of it.
//   graspsim_echo_server [--listen=127.0.0.1:0]   prints "port=<n>" once listening, serves until killed
#include <cstdio>
#include <memory>
#include <string>

#include <absl/synchronization/mutex.h>
#include <grpcpp/grpcpp.h>

#include "echo.grpc.pb.h"

namespace {

class EchoService final : public graspsim::bench::Echo::CallbackService {
  grpc::ServerUnaryReactor* Echo(grpc::CallbackServerContext* context, const graspsim::bench::EchoMessage* request,
                                 graspsim::bench::EchoMessage* reply) override {
    *reply = *request;
    grpc::ServerUnaryReactor* reactor = context->DefaultReactor();
    reactor->Finish(grpc::Status::OK);
    return reactor;
  }
};

}  // namespace

int main(int argc, char** argv) {
  std::string listen = "127.0.0.1:0";
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg.rfind("--listen=", 0) == 0) {
      listen = arg.substr(9);
    } else {
      std::fprintf(stderr, "graspsim_echo_server: unknown argument '%s' (only --listen=host:port)\n", argv[i]);
      return 2;
    }
  }
  absl::SetMutexDeadlockDetectionMode(absl::OnDeadlockCycle::kIgnore);  // as graspsim-server (app/main.cpp)
  EchoService service;
  int port = 0;
  grpc::ServerBuilder builder;
  builder.AddListeningPort(listen, grpc::InsecureServerCredentials(), &port);
  builder.AddChannelArgument(GRPC_ARG_ALLOW_REUSEPORT, 0);
  builder.RegisterService(&service);
  const std::unique_ptr<grpc::Server> server = builder.BuildAndStart();
  if (!server || port == 0) {
    std::fprintf(stderr, "graspsim_echo_server: cannot listen on '%s'\n", listen.c_str());
    return 1;
  }
  std::printf("port=%d\n", port);
  std::fflush(stdout);
  server->Wait();
}
