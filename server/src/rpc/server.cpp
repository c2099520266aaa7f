#include "rpc/server.h"

#include <chrono>
#include <cstdlib>

#include <grpcpp/ext/proto_server_reflection_plugin.h>
#include <grpcpp/health_check_service_interface.h>

#include "core/error.h"
#include "core/format.h"
#include "core/log.h"
#include "edits/scene_restore.h"
#include "rpc/auth_service.h"
#include "rpc/gateway_service.h"
#include "rpc/grasp_service.h"
#include "rpc/perception_service.h"
#include "rpc/scene_edits.h"
#include "rpc/foxglove_live.h"
#include "rpc/scene_service.h"
#include "rpc/tactile_service.h"

namespace graspsim::rpc {

std::string DefaultGraspDataDir() {
  if (const char* xdg = std::getenv("XDG_DATA_HOME"); xdg != nullptr && *xdg != '\0') return std::string(xdg) + "/graspsim";
  if (const char* home = std::getenv("HOME"); home != nullptr && *home != '\0') return std::string(home) + "/.local/share/graspsim";
  return "graspsim-data";
}

namespace {

bool IsLoopback(const std::string& address) {
  if (address.starts_with("unix:")) return true;  // a socket file: local by construction
  const size_t colon = address.rfind(':');
  std::string host = colon == std::string::npos ? address : address.substr(0, colon);
  if (host.size() >= 2 && host.front() == '[' && host.back() == ']') host = host.substr(1, host.size() - 2);
  return host == "localhost" || host == "::1" || host.starts_with("127.");
}

}  // namespace

void CheckListenSecurity(const ServerOptions& options) {
  const TlsFiles& tls = options.tls;
  if (tls.cert.empty() != tls.key.empty()) ThrowInvalidArgument("--tls-cert and --tls-key: give both or neither");
  if (!tls.client_ca.empty() && tls.cert.empty()) ThrowInvalidArgument("--tls-client-ca: needs --tls-cert and --tls-key");
  if (options.insecure && !tls.cert.empty()) ThrowInvalidArgument("--insecure: contradicts --tls-cert");
  std::vector<std::pair<std::string, std::string>> addresses = {{"listen", options.listen}};
  if (options.http_enabled) addresses.emplace_back("http-listen", options.http.listen);
  for (const auto& [flag, address] : addresses) {
    if (IsLoopback(address)) continue;
    if (options.insecure || tls.cert.empty()) {
      ThrowInvalidArgument("--" + flag + ": '" + address + "' is not a loopback address; serving it needs " +
                           "--tls-cert and --tls-key (--insecure is accepted only for 127.0.0.1, ::1 and localhost)");
    }
    if (options.token_file.empty()) {
      ThrowInvalidArgument("--" + flag + ": '" + address + "' is not a loopback address; serving it needs " +
                           "--token-file (docs/security.md), so that only callers with a token get in");
    }
  }
  // The live Foxglove endpoint has neither TLS nor tokens: it shows any scene to whoever connects.
  if (options.foxglove_listen != "off" && !IsLoopback(options.foxglove_listen)) {
    ThrowInvalidArgument("--foxglove-listen: '" + options.foxglove_listen +
                         "' is not a loopback address; the live endpoint has no TLS or tokens (docs/recording.md)");
  }
}

GraspsimServer::GraspsimServer(const ServerOptions& options)
    : options_(options), registry_(options.limits), pool_(options.worker_threads) {
  CheckListenSecurity(options);
  if (!options.token_file.empty()) {
    authorizer_.LoadTokenFile(options.token_file);
    const std::string auth_dir = options.auth_data_dir.empty() ? options.data_dir : options.auth_data_dir;
    if (auth_dir != "off") authorizer_.OpenStore(auth_dir);
  }
  if (options.data_dir != "off") {
    // Before any service exists: a store that cannot be opened or replayed stops the start, naming the file.
    const auto start = std::chrono::steady_clock::now();
    scene_store_ = std::make_unique<persistence::SceneStore>(options.data_dir);
    const size_t restored =
        edits::RestoreScenes(scene_store_.get(), &registry_, LegacyEditReaderFor(registry_.limits()));
    Log(LogLevel::kInfo, "scenes restored",
        {{"path", scene_store_->path()}, {"scenes", std::to_string(restored)},
         {"ms", FormatNumber(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count())}});
  }
  grpc::EnableDefaultHealthCheckService(true);
  grpc::reflection::InitProtoReflectionServerBuilderPlugin();

  {
    std::string recording_dir = options.recording_dir;
    if (recording_dir.empty() && options.data_dir != "off") recording_dir = options.data_dir + "/recordings";
    auto recordings = std::make_unique<RecordingServiceImpl>(&registry_, &pool_, recording_dir);
    recordings_ = recordings.get();
    services_.push_back(std::move(recordings));
    if (options.record_all) {  // --record: restored scenes from now on, new ones from their creation
      for (const auto& scene : registry_.List()) recordings_->RecordAutomatically(scene);
      registry_.SetCreatedHook([this](const std::shared_ptr<Scene>& scene) { recordings_->RecordAutomatically(scene); });
    }
  services_.push_back(
      std::make_unique<SceneServiceImpl>(&registry_, &pool_, &simulations_, options.watch_max_rate_hz));
  services_.push_back(std::make_unique<PerceptionServiceImpl>(&registry_, &pool_, &overlays_, recordings_));
  std::shared_ptr<grasp::GraspStore> grasp_store;
  const std::string grasp_dir = options.grasp_data_dir.empty() ? options.data_dir : options.grasp_data_dir;
  if (grasp_dir != "off") grasp_store = std::make_shared<grasp::GraspStore>(grasp_dir);
  services_.push_back(std::make_unique<GraspServiceImpl>(&registry_, &pool_, std::move(grasp_store), &overlays_));
  services_.push_back(
      std::make_unique<TactileServiceImpl>(&registry_, &pool_, &simulations_, options.watch_max_rate_hz));
  services_.push_back(std::make_unique<GatewayServiceImpl>(&gateways_, &registry_, &pool_, recordings_));
  services_.push_back(std::make_unique<AuthServiceImpl>(&authorizer_, !options.token_file.empty(), &pool_));
  }

  grpc::ServerBuilder builder;
  // Loopback by default; wider addresses need TLS (CheckListenSecurity). docs/security.md.
  builder.AddListeningPort(options.listen, ServerCredentials(options.tls), &port_);
  {
    std::vector<std::unique_ptr<grpc::experimental::ServerInterceptorFactoryInterface>> interceptors;
    interceptors.push_back(MakeInterceptorFactory(
        &authorizer_, {.tokens = !options.token_file.empty(), .gateway_needs_cert = !options.tls.client_ca.empty()}));
    builder.experimental().SetInterceptorCreators(std::move(interceptors));
  }
  if (options.tls.cert.empty()) {
    Log(LogLevel::kWarn, "INSECURE: no TLS (no --tls-cert); plaintext on loopback only, never expose this port",
        {{"listen", options.listen}});
  }
  if (options.token_file.empty()) {
    Log(LogLevel::kWarn, "AUTH OFF: no --token-file; every caller may do everything", {});
  } else {
    Log(LogLevel::kInfo, "tokens loaded", {{"file", options.token_file}, {"tokens", std::to_string(authorizer_.token_count())}});
  }
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
    HttpGatewayOptions http = options.http;
    http.tls_cert = options.tls.cert;
    http.tls_key = options.tls.key;
    http.overlays = &overlays_;
    http_ = std::make_unique<HttpGateway>(server_->InProcessChannel(arguments), http);
  }
  if (options.foxglove_listen != "off") {
    foxglove_ = StartFoxgloveLive(options.foxglove_listen, &registry_);
    Log(LogLevel::kInfo, "foxglove live endpoint", {{"address", options.foxglove_listen},
                                                    {"port", std::to_string(foxglove_->port())}});
  }
}

GraspsimServer::~GraspsimServer() { Shutdown(); }

void GraspsimServer::Shutdown() {
  if (!server_) return;
  Log(LogLevel::kInfo, "draining", {{"timeout_s", FormatNumber(options_.drain_timeout_s)}});
  server_->GetHealthCheckService()->Shutdown();
  // Watch streams never end by themselves: end them first so that draining waits only for real work.
  foxglove_.reset();  // its live feeds are watchers too
  registry_.CloseAllWatchers("the server is shutting down");
  recordings_->StopAll();  // their files get their summary and footer
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
