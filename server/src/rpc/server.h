// The gRPC server: every v1 service, health checking and reflection, on one port.
#pragma once

#include <memory>
#include <string>

#include <grpcpp/grpcpp.h>

#include "auth/auth.h"
#include "core/limits.h"
#include "core/worker_pool.h"
#include "gateway/gateway_hub.h"
#include "physics/simulation_cache.h"
#include "persistence/scene_store.h"
#include "live/foxglove_server.h"
#include "rpc/auth_interceptor.h"
#include "rpc/http_gateway.h"
#include "rpc/recording_service.h"
#include "rpc/scene_overlays.h"
#include "world/scene_registry.h"

namespace graspsim::rpc {

std::string DefaultGraspDataDir();

struct ServerOptions {
  std::string listen = "127.0.0.1:50051";
  int max_message_bytes = 4 << 20;
  double watch_max_rate_hz = 60;
  double drain_timeout_s = 10;
  int worker_threads = 16;  // request bodies run here, off gRPC's threads
  Limits limits;
  // Scenes survive restarts here (scenes.sqlite, docs/durability.md); "off" keeps them in memory only. The
  // default follows the XDG base directories: $XDG_DATA_HOME/graspsim, else $HOME/.local/share/graspsim, else
  // ./graspsim-data.
  std::string data_dir = DefaultGraspDataDir();
  // Grasp sets survive restarts here (grasp_sets.sqlite); "off" stores nothing, empty = data_dir.
  std::string grasp_data_dir;
  bool http_enabled = true;
  HttpGatewayOptions http;
  // Security (docs/security.md): TLS on both ports from these PEM files; without them only loopback addresses
  // are served (plaintext, with a warning), and `insecure` says so explicitly. A token file turns on bearer
  // tokens and roles.
  TlsFiles tls;
  bool insecure = false;
  std::string token_file;
  // Tokens added or revoked by AuthService, scene owners, shares and grants (auth.sqlite); empty = data_dir,
  // "off" = kept in memory only.
  std::string auth_data_dir;
  // Recordings (docs/recording.md): where they are written (empty = <data_dir>/recordings, none when data_dir is
  // off), whether every scene is recorded from its creation (--record), and the live Foxglove endpoint.
  std::string recording_dir;
  bool record_all = false;
  std::string foxglove_listen = "off";
};

// Throws Error(kInvalidArgument) when the listen addresses and the TLS flags do not go together.
void CheckListenSecurity(const ServerOptions& options);

class GraspsimServer {
 public:
  // Binds and starts serving; throws Error(kFailedPrecondition) when the address cannot be bound.
  explicit GraspsimServer(const ServerOptions& options);
  ~GraspsimServer();

  int port() const { return port_; }
  int http_port() const { return http_ ? http_->port() : 0; }
  // Ends watcher streams, lets in-flight requests finish within drain_timeout_s, then stops.
  void Shutdown();

 private:
  ServerOptions options_;
  auth::Authorizer authorizer_;  // tokens, roles, scene owners: read by the interceptor of every call
  std::unique_ptr<persistence::SceneStore> scene_store_;  // null with data_dir "off"; outlives the registry
  SceneRegistry registry_;
  WorkerPool pool_;
  SimulationCache simulations_;  // one Simulation per scene, shared by the services that step scenes
  gateway::GatewayHub gateways_;  // the hardware gateways' devices and the commands in flight to them
  SceneOverlays overlays_;        // completions' planes and planned arm paths, for the viewer
  std::vector<std::unique_ptr<grpc::Service>> services_;
  std::unique_ptr<grpc::Server> server_;
  std::unique_ptr<HttpGateway> http_;
  RecordingServiceImpl* recordings_ = nullptr;  // one of services_
  std::unique_ptr<live::FoxgloveServer> foxglove_;
  int port_ = 0;
};

}  // namespace graspsim::rpc
