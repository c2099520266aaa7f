#include "app/flags.h"

#include <cmath>
#include <fstream>
#include <functional>
#include <map>
#include <sstream>
#include <vector>

#include "core/error.h"
#include "core/format.h"

namespace graspsim {
namespace {

struct FlagSpec {
  std::string name, help;
  std::function<std::string(const ServerFlags&)> show;
  std::function<void(const std::string&, ServerFlags*)> set;
};

uint64_t ParseCount(const std::string& flag, const std::string& text, uint64_t min) {
  size_t used = 0;
  unsigned long long value = 0;
  try {
    value = std::stoull(text, &used);
  } catch (const std::exception&) {
    used = 0;
  }
  if (used == 0 || used != text.size() || text.front() == '-' || value < min) {
    ThrowInvalidArgument("--" + flag + ": '" + text + "' is not an integer >= " + std::to_string(min));
  }
  return value;
}

double ParsePositive(const std::string& flag, const std::string& text) {
  size_t used = 0;
  double value = 0;
  try {
    value = std::stod(text, &used);
  } catch (const std::exception&) {
    used = 0;
  }
  if (used == 0 || used != text.size() || !std::isfinite(value) || value <= 0) {
    ThrowInvalidArgument("--" + flag + ": '" + text + "' is not a positive number");
  }
  return value;
}

const std::vector<FlagSpec>& Specs() {
  static const std::vector<FlagSpec> specs = {
      {"listen", "address to serve gRPC on, host:port (port 0 = any free port)",
       [](const ServerFlags& f) { return f.server.listen; },
       [](const std::string& v, ServerFlags* f) { f->server.listen = v; }},
      {"http-listen", "address of the HTTP/JSON gateway (POST /v1/<Service>/<Method>), host:port, or off",
       [](const ServerFlags& f) { return f.server.http_enabled ? f.server.http.listen : std::string("off"); },
       [](const std::string& v, ServerFlags* f) {
         f->server.http_enabled = v != "off";
         if (f->server.http_enabled) f->server.http.listen = v;
       }},
      {"http-threads", "HTTP requests served at once (each open event stream holds one)",
       [](const ServerFlags& f) { return std::to_string(f.server.http.threads); },
       [](const std::string& v, ServerFlags* f) {
         f->server.http.threads = static_cast<int>(std::min<uint64_t>(ParseCount("http-threads", v, 1), 4096));
       }},
      {"viewer-dir", "files of the browser viewer served under /view (empty = share/graspsim/viewer beside bin/)",
       [](const ServerFlags& f) { return f.server.http.viewer_dir; },
       [](const std::string& v, ServerFlags* f) { f->server.http.viewer_dir = v; }},
      {"http-max-body-bytes", "largest HTTP request body, bytes",
       [](const ServerFlags& f) { return std::to_string(f.server.http.max_body_bytes); },
       [](const std::string& v, ServerFlags* f) { f->server.http.max_body_bytes = ParseCount("http-max-body-bytes", v, 1); }},
      {"log-level", "debug (one line per request), info, warn or error",
       [](const ServerFlags&) { return std::string("info"); },
       [](const std::string& v, ServerFlags* f) {
         if (!ParseLogLevel(v, &f->log_level)) {
           ThrowInvalidArgument("--log-level: '" + v + "' is not one of debug, info, warn, error");
         }
       }},
      {"max-message-bytes", "largest request message, bytes; bigger files go through UploadFile in chunks",
       [](const ServerFlags& f) { return std::to_string(f.server.max_message_bytes); },
       [](const std::string& v, ServerFlags* f) {
         f->server.max_message_bytes = static_cast<int>(std::min<uint64_t>(ParseCount("max-message-bytes", v, 1024), 1 << 30));
       }},
      {"max-scenes", "scenes the server holds at most",
       [](const ServerFlags& f) { return std::to_string(f.server.limits.max_scenes); },
       [](const std::string& v, ServerFlags* f) { f->server.limits.max_scenes = ParseCount("max-scenes", v, 1); }},
      {"max-bodies-per-scene", "bodies (objects and robot links) per scene",
       [](const ServerFlags& f) { return std::to_string(f.server.limits.max_bodies_per_scene); },
       [](const std::string& v, ServerFlags* f) {
         f->server.limits.max_bodies_per_scene = ParseCount("max-bodies-per-scene", v, 1);
       }},
      {"max-triangles-per-mesh", "triangles per mesh",
       [](const ServerFlags& f) { return std::to_string(f.server.limits.max_triangles_per_mesh); },
       [](const std::string& v, ServerFlags* f) {
         f->server.limits.max_triangles_per_mesh = ParseCount("max-triangles-per-mesh", v, 1);
       }},
      {"max-upload-bytes", "bytes of one uploaded file",
       [](const ServerFlags& f) { return std::to_string(f.server.limits.max_upload_bytes); },
       [](const std::string& v, ServerFlags* f) {
         f->server.limits.max_upload_bytes = ParseCount("max-upload-bytes", v, 1);
       }},
      {"max-cloud-points", "points of a cloud or pixels of a depth image (PerceptionService)",
       [](const ServerFlags& f) { return std::to_string(f.server.limits.max_cloud_points); },
       [](const std::string& v, ServerFlags* f) {
         f->server.limits.max_cloud_points = ParseCount("max-cloud-points", v, 1);
       }},
      {"max-scene-file-bytes", "bytes of all files of one scene",
       [](const ServerFlags& f) { return std::to_string(f.server.limits.max_scene_file_bytes); },
       [](const std::string& v, ServerFlags* f) {
         f->server.limits.max_scene_file_bytes = ParseCount("max-scene-file-bytes", v, 1);
       }},
      {"watch-max-rate-hz", "most snapshots per second a WatchScene stream gets, Hz",
       [](const ServerFlags& f) { return FormatNumber(f.server.watch_max_rate_hz); },
       [](const std::string& v, ServerFlags* f) { f->server.watch_max_rate_hz = ParsePositive("watch-max-rate-hz", v); }},
      {"worker-threads", "threads that run request bodies (long simulation runs hold one each)",
       [](const ServerFlags& f) { return std::to_string(f.server.worker_threads); },
       [](const std::string& v, ServerFlags* f) {
         f->server.worker_threads = static_cast<int>(std::min<uint64_t>(ParseCount("worker-threads", v, 1), 1024));
       }},
      {"compute-threads", "threads of the pool every parallel stage shares (grasp planning, mesh parsing); 0 = the "
                          "cores this process may use, container CPU quota included (docs/scaling.md)",
       [](const ServerFlags& f) { return std::to_string(f.compute_threads); },
       [](const std::string& v, ServerFlags* f) {
         f->compute_threads = static_cast<size_t>(std::min<uint64_t>(ParseCount("compute-threads", v, 0), 1024));
       }},
      {"drain-timeout-s", "on SIGTERM, how long in-flight requests may finish before they are cancelled, s",
       [](const ServerFlags& f) { return FormatNumber(f.server.drain_timeout_s); },
       [](const std::string& v, ServerFlags* f) { f->server.drain_timeout_s = ParsePositive("drain-timeout-s", v); }},
      {"data-dir", "directory of the scene store (scenes.sqlite: scenes survive restarts and crashes, "
                   "docs/durability.md), or off to keep scenes in memory only",
       [](const ServerFlags& f) { return f.server.data_dir; },
       [](const std::string& v, ServerFlags* f) {
         if (v.empty()) ThrowInvalidArgument("--data-dir: empty; give a directory or off");
         f->server.data_dir = v;
       }},
      {"grasp-data-dir", "directory of the grasp-set store (grasp_sets.sqlite), or off to store nothing "
                         "(empty = --data-dir)",
       [](const ServerFlags& f) { return f.server.grasp_data_dir; },
       [](const std::string& v, ServerFlags* f) {
         if (v.empty()) ThrowInvalidArgument("--grasp-data-dir: empty; give a directory or off");
         f->server.grasp_data_dir = v;
       }},
      // Recordings (docs/recording.md).
      {"record", "record every scene from its creation as MCAP into this directory (also where StartRecording "
                 "writes), or off",
       [](const ServerFlags& f) { return f.server.record_all ? f.server.recording_dir : std::string("off"); },
       [](const std::string& v, ServerFlags* f) {
         if (v.empty()) ThrowInvalidArgument("--record: empty; give a directory or off");
         f->server.record_all = v != "off";
         if (f->server.record_all) f->server.recording_dir = v;
       }},
      {"recording-dir", "where StartRecording writes and ReplayRecording reads (empty = <data-dir>/recordings)",
       [](const ServerFlags& f) { return f.server.recording_dir; },
       [](const std::string& v, ServerFlags* f) { f->server.recording_dir = v; }},
      {"foxglove-listen", "address of the live Foxglove WebSocket endpoint (ws://host:port/<scene id>), host:port, "
                          "or off",
       [](const ServerFlags& f) { return f.server.foxglove_listen; },
       [](const std::string& v, ServerFlags* f) {
         if (v.empty()) ThrowInvalidArgument("--foxglove-listen: empty; give host:port or off");
         f->server.foxglove_listen = v;
       }},
      // Security (docs/security.md).
      {"tls-cert", "PEM certificate (chain) of the gRPC and HTTP ports; with --tls-key turns TLS on",
       [](const ServerFlags& f) { return f.server.tls.cert; },
       [](const std::string& v, ServerFlags* f) { f->server.tls.cert = v; }},
      {"tls-key", "PEM private key of --tls-cert",
       [](const ServerFlags& f) { return f.server.tls.key; },
       [](const std::string& v, ServerFlags* f) { f->server.tls.key = v; }},
      {"tls-client-ca", "PEM CA of client certificates: requested from every client, required for GatewayService/Connect",
       [](const ServerFlags& f) { return f.server.tls.client_ca; },
       [](const std::string& v, ServerFlags* f) { f->server.tls.client_ca = v; }},
      {"insecure", "true: serve plaintext on purpose (loopback addresses only; also the default there without --tls-cert)",
       [](const ServerFlags& f) { return std::string(f.server.insecure ? "true" : "false"); },
       [](const std::string& v, ServerFlags* f) {
         if (v != "true" && v != "false") ThrowInvalidArgument("--insecure: '" + v + "' is not true or false");
         f->server.insecure = v == "true";
       }},
      {"token-file", "bearer tokens and roles ('<role> <name> <token>' lines, docs/security.md); empty = auth off",
       [](const ServerFlags& f) { return f.server.token_file; },
       [](const std::string& v, ServerFlags* f) { f->server.token_file = v; }},
      {"auth-data-dir", "directory of auth.sqlite (tokens added or revoked by AuthService, scene owners, shares, "
                        "grants), or off (empty = --data-dir)",
       [](const ServerFlags& f) { return f.server.auth_data_dir; },
       [](const std::string& v, ServerFlags* f) { f->server.auth_data_dir = v; }},
  };
  return specs;
}

const FlagSpec& Find(const std::string& name) {
  for (const auto& spec : Specs()) {
    if (spec.name == name) return spec;
  }
  ThrowInvalidArgument("--" + name + ": unknown flag (see --help)");
}

std::string Trim(const std::string& s) {
  const size_t begin = s.find_first_not_of(" \t\r");
  if (begin == std::string::npos) return "";
  return s.substr(begin, s.find_last_not_of(" \t\r") - begin + 1);
}

void ApplyConfigFile(const std::string& path, ServerFlags* flags) {
  std::ifstream file(path);
  if (!file) ThrowInvalidArgument("--config: cannot read '" + path + "'");
  std::string line;
  for (int number = 1; std::getline(file, line); ++number) {
    line = Trim(line.substr(0, line.find('#')));
    if (line.empty()) continue;
    const size_t eq = line.find('=');
    if (eq == std::string::npos) {
      ThrowInvalidArgument("--config: " + path + ":" + std::to_string(number) + ": expected 'name = value'");
    }
    const std::string name = Trim(line.substr(0, eq));
    if (name == "config") ThrowInvalidArgument("--config: " + path + ": a config file cannot name another");
    Find(name).set(Trim(line.substr(eq + 1)), flags);
  }
}

}  // namespace

ServerFlags ParseFlags(int argc, char** argv) {
  std::vector<std::pair<std::string, std::string>> given;
  for (int i = 1; i < argc; ++i) {
    std::string arg = argv[i];
    if (arg == "--help" || arg == "-h") {
      ServerFlags flags;
      flags.help = true;
      return flags;
    }
    if (!arg.starts_with("--")) ThrowInvalidArgument("'" + arg + "': expected --name=value");
    arg = arg.substr(2);
    const size_t eq = arg.find('=');
    if (eq != std::string::npos) {
      given.emplace_back(arg.substr(0, eq), arg.substr(eq + 1));
    } else if (arg == "insecure") {  // the one flag that may stand alone
      given.emplace_back(arg, "true");
    } else if (i + 1 < argc) {
      given.emplace_back(arg, argv[++i]);
    } else {
      ThrowInvalidArgument("--" + arg + ": missing value");
    }
  }
  ServerFlags flags;
  // The config file first, so that the command line overrides it wherever it appears.
  for (const auto& [name, value] : given) {
    if (name == "config") ApplyConfigFile(value, &flags);
  }
  for (const auto& [name, value] : given) {
    if (name != "config") Find(name).set(value, &flags);
  }
  return flags;
}

std::string FlagsHelp() {
  std::ostringstream out;
  out << "graspsim-server: the graspsim simulation server (gRPC API graspsim.v1, health and reflection on).\n\n"
         "Usage: graspsim-server [--name=value ...]\n\n"
         "  --config=FILE                       read flags from FILE: 'name = value' lines, '#' comments; the command line wins\n"
         "  --help                              print this help\n";
  const ServerFlags defaults;
  for (const auto& spec : Specs()) {
    std::string left = "  --" + spec.name + "=" + spec.show(defaults);
    if (left.size() < 38) left.resize(38, ' ');
    out << left << " " << spec.help << "\n";
  }
  out << "\nSIGTERM or SIGINT drains in-flight requests (up to --drain-timeout-s) and exits 0.\n";
  return out.str();
}

}  // namespace graspsim
