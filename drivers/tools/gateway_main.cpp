// graspsim-gateway: runs on the robot PC, puts its grippers behind the server's GatewayService.
//   graspsim-gateway --server=HOST:PORT --device=SPEC [--device=SPEC ...] [--name=NAME] [--limits=LIST]
//                    [--watchdog-ms=200] [--reading-ms=20] [--device-timeout-ms=200] [--backoff-max-ms=5000]
//                    [--no-initialize] [--log-level=info] [--tls-ca=PEM [--tls-cert=PEM --tls-key=PEM]] [--token-file=FILE]
// SPEC: [ID=]robotiq-tcp:HOST:PORT | [ID=]robotiq-rtu:DEVICE | [ID=]pg70-can:IFACE[:MODULE] | [ID=]pg70-fd:FD[:MODULE]
// LIST: name=value,... narrowing every device's limits (min_opening, max_opening m; min_speed, max_speed m/s;
// min_force, max_force N). Runs until SIGINT or SIGTERM, then stops every device and exits 0.
// Under systemd (Type=notify): READY=1 once the devices are open and initialised, WATCHDOG=1 while its loops are
// alive (sd_notify.h; deploy/systemd/graspsim-gateway.service).
#include <unistd.h>

#include <csignal>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <string>
#include <thread>
#include <vector>

#include "core/error.h"
#include "core/log.h"
#include "drivers/gateway/device_spec.h"
#include "drivers/gateway/gateway_client.h"
#include "drivers/tools/sd_notify.h"

namespace {

using namespace graspsim;
using namespace graspsim::drivers::gateway;
namespace sdnotify = graspsim::drivers::sdnotify;

// The first word of the file: a token on the command line would show in every process listing.
std::string ReadToken(const std::string& path) {
  std::ifstream file(path);
  std::string token;
  if (!file || !(file >> token)) ThrowInvalidArgument("--token-file: cannot read a token from '" + path + "'");
  return token;
}

int Usage(const std::string& error) {
  if (!error.empty()) std::fprintf(stderr, "graspsim-gateway: %s\n", error.c_str());
  std::fprintf(stderr,
               "usage: graspsim-gateway --server=HOST:PORT --device=SPEC [--device=SPEC ...] [--name=NAME]\n"
               "         [--limits=name=value,...] [--watchdog-ms=200] [--reading-ms=20] [--device-timeout-ms=200]\n"
               "         [--backoff-max-ms=5000] [--no-initialize] [--log-level=info]\n"
               "         [--tls-ca=PEM [--tls-cert=PEM --tls-key=PEM]] [--token-file=FILE]\n"
               "  SPEC: [ID=]robotiq-tcp:HOST:PORT | [ID=]robotiq-rtu:DEVICE | [ID=]pg70-can:IFACE[:MODULE]\n"
               "        | [ID=]pg70-fd:FD[:MODULE]\n");
  return 2;
}

int Milliseconds(const std::string& flag, const std::string& text, int low, int high) {
  size_t used = 0;
  int value = -1;
  try {
    value = std::stoi(text, &used);
  } catch (const std::exception&) {
  }
  if (used != text.size() || value < low || value > high) {
    ThrowInvalidArgument("--" + flag + ": '" + text + "' is not an integer in [" + std::to_string(low) + ", " +
                         std::to_string(high) + "]");
  }
  return value;
}

GatewayClient* g_client = nullptr;

}  // namespace

int main(int argc, char** argv) {
  GatewayOptions options;
  char host[256] = "gateway";
  if (gethostname(host, sizeof(host) - 1) == 0) options.name = host;
  std::vector<std::string> device_flags;
  std::string limits;
  int device_timeout_ms = 200;
  bool initialize = true;
  try {
    for (int i = 1; i < argc; ++i) {
      const std::string arg = argv[i];
      const size_t eq = arg.find('=');
      const std::string name = arg.substr(0, eq), value = eq == std::string::npos ? "" : arg.substr(eq + 1);
      if (name == "--help") return Usage("");
      if (name == "--server") options.server = value;
      else if (name == "--name") options.name = value;
      else if (name == "--tls-ca") options.tls_ca = value;
      else if (name == "--tls-cert") options.tls_cert = value;
      else if (name == "--tls-key") options.tls_key = value;
      else if (name == "--token-file") options.token = ReadToken(value);
      else if (name == "--device") device_flags.push_back(value);
      else if (name == "--limits") limits = value;
      else if (name == "--watchdog-ms") options.watchdog = std::chrono::milliseconds(Milliseconds("watchdog-ms", value, 10, 60000));
      else if (name == "--reading-ms") options.reading_period = std::chrono::milliseconds(Milliseconds("reading-ms", value, 1, 60000));
      else if (name == "--device-timeout-ms") device_timeout_ms = Milliseconds("device-timeout-ms", value, 1, 60000);
      else if (name == "--backoff-max-ms") options.backoff_max = std::chrono::milliseconds(Milliseconds("backoff-max-ms", value, 100, 600000));
      else if (name == "--no-initialize") initialize = false;
      else if (name == "--log-level") {
        LogLevel level;
        if (!ParseLogLevel(value, &level)) return Usage("--log-level: '" + value + "' is not debug, info, warn or error");
        SetLogLevel(level);
      } else {
        return Usage("unknown flag '" + arg + "'");
      }
    }
    if (device_flags.empty()) return Usage("no --device given");
    if (options.name.empty()) return Usage("--name: empty");
    std::vector<std::unique_ptr<GuardedDevice>> devices;
    for (size_t i = 0; i < device_flags.size(); ++i) {
      const DeviceSpec spec = ParseDeviceSpec(device_flags[i], static_cast<int>(i));
      for (const auto& other : devices) {
        if (other->id() == spec.id) return Usage("--device: id '" + spec.id + "' given twice");
      }
      devices.push_back(OpenDevice(spec, limits, std::chrono::milliseconds(device_timeout_ms)));
      if (initialize) {
        try {
          devices.back()->Initialize();
        } catch (const Error& error) {  // registered anyway: 'initialize' retries, the readings show the fault
          Log(LogLevel::kError, "initialize failed", {{"device", spec.id}, {"error", error.what()}});
        }
      }
      Log(LogLevel::kInfo, "device ready", {{"device", spec.id}, {"link", devices.back()->link()}});
    }
    sdnotify::WatchdogPinger pinger(sdnotify::WatchdogInterval());
    if (pinger.enabled()) options.alive = [&pinger] { pinger.Ping(); };
    GatewayClient client(options, std::move(devices));
    g_client = &client;
    std::signal(SIGINT, [](int) { g_client->Shutdown(); });
    std::signal(SIGTERM, [](int) { g_client->Shutdown(); });
    std::signal(SIGPIPE, SIG_IGN);
    // Ready without waiting for the server: reconnecting is the gateway's own job, not a failed start.
    sdnotify::Notify("READY=1");
    client.Run();
    return 0;
  } catch (const Error& error) {
    Usage(error.what());
    return 1;
  }
}
