#include "rpc/server.h"

#include <chrono>
#include <cstdlib>

#include <grpcpp/ext/proto_server_reflection_plugin.h>
#include <grpcpp/health_check_service_interface.h>

#include "core/error.h"
#include "core/format.h"
#include "core/log.h"
#include "rpc/gateway_service.h"
#include "rpc/grasp_service.h"
#include "rpc/perception_service.h"
#include "rpc/scene_service.h"
#include "rpc/tactile_service.h"

namespace graspsim::rpc {

std::string DefaultGraspDataDir() {
  if (const char* xdg = std::getenv("XDG_DATA_HOME"); xdg != nullptr && *xdg != '\0') return std::string(xdg) + "/graspsim";
  if (const char* home = std::getenv("HOME"); home != nullptr && *home != '\0') return std::string(home) + "/.local/share/graspsim";
  return "graspsim-data";
}

GraspsimServer::GraspsimServer(const ServerOptions& options)
    : options_(options), registry_(options.limits), pool_(options.worker_threads) {
  grpc::EnableDefaultHealthCheckService(true);
  grpc::reflection::InitProtoReflectionServerBuilderPlugin();

  services_.push_back(
      std::make_unique<SceneServiceImpl>(&registry_, &pool_, &simulations_, options.watch_max_rate_hz));
  services_.push_back(std::make_unique<PerceptionServiceImpl>(&registry_, &pool_));
  std::shared_ptr<grasp::GraspStore> grasp_store;
  if (options.grasp_data_dir != "off") grasp_store = std::make_shared<grasp::GraspStore>(options.grasp_data_dir);
  services_.push_back(std::make_unique<GraspServiceImpl>(&registry_, &pool_, std::move(grasp_store)));
  services_.push_back(
      std::make_unique<TactileServiceImpl>(&registry_, &pool_, &simulations_, options.watch_max_rate_hz));
  services_.push_back(std::make_unique<GatewayServiceImpl>(&gateways_, &registry_, &pool_));

  grpc::ServerBuilder builder;
  // Loopback by default; wider addresses get TLS with the security issue.
  builder.AddListeningPort(options.listen, grpc::InsecureServerCredentials(), &port_);
  // Without this a second server on the same port would start and silently share its traffic (SO_REUSEPORT).
  builder.AddChannelArgument(GRPC_ARG_ALLOW_REUSEPORT, 0);
  builder.SetMaxReceiveMessageSize(options.max_message_bytes);
  builder.SetMaxSendMessageSize(-1);  // a GetScene with geometry may be large; the client sets its own limit
  for (auto& service : services_) builder.RegisterService(service.get());
  server_ = builder.BuildAndStart();
  if (!server_ || port_ == 0) {
    throw Error(ErrorCode::kFailedPrecondition, "--listen: cannot listen on '" + options.listen + "'");
  }
  Log(LogLevel::kInfo, "listening", {{"address", options.listen}, {"port", std::to_string(port_)}});
  if (options.http_enabled) {
    grpc::ChannelArguments arguments;
    arguments.SetMaxReceiveMessageSize(-1);  // the server's own limits apply; the gateway adds none
    http_ = std::make_unique<HttpGateway>(server_->InProcessChannel(arguments), options.http);
  }
}

GraspsimServer::~GraspsimServer() { Shutdown(); }

void GraspsimServer::Shutdown() {
  if (!server_) return;
  Log(LogLevel::kInfo, "draining", {{"timeout_s", FormatNumber(options_.drain_timeout_s)}});
  server_->GetHealthCheckService()->Shutdown();
  // Watch streams never end by themselves: end them first so that draining waits only for real work.
  registry_.CloseAllWatchers("the server is shutting down");
  gateways_.EndAll("the server is shutting down");
  if (http_) http_->Stop();  // waits for HTTP requests in flight; they still reach the running gRPC server
  const auto deadline =
      std::chrono::system_clock::now() + std::chrono::duration<double>(options_.drain_timeout_s);
  server_->Shutdown(std::chrono::time_point_cast<std::chrono::system_clock::duration>(deadline));
  server_->Wait();
  server_.reset();
  Log(LogLevel::kInfo, "stopped");
}

}  // namespace graspsim::rpc
