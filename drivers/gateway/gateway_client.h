// The graspsim-gateway's link to the server: GatewayService.Connect as a synchronous bidi stream. Per session it
// registers every device, then relays the server's commands to the devices and their readings and results back.
// The link is lost when the stream ends (reconnect with exponential backoff, devices stopped at once) or when the
// server has been silent longer than the watchdog time while the stream stays up (a stalled or partitioned
// server: devices stopped, work resumes with the next command once messages flow again). E-stop latches
// (GuardedDevice); the watchdog's stop does not.
//
// Threads: Run's thread reads the stream; one thread per device executes its commands in order and polls its
// readings; one watchdog thread. Stop and e-stop commands jump the device's queue and drop what waits in it.
#pragma once

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <deque>
#include <functional>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "drivers/gateway/guarded_device.h"

namespace graspsim::v1 {
class DeviceCommand;
class GatewayMessage;
}  // namespace graspsim::v1

namespace graspsim::drivers::gateway {

struct GatewayOptions {
  std::string server = "127.0.0.1:50051";
  std::string name = "gateway";
  std::chrono::milliseconds watchdog{200};
  std::chrono::milliseconds reading_period{20};
  std::chrono::milliseconds backoff_initial{100};
  std::chrono::milliseconds backoff_max{5000};
  // Security (docs/security.md): PEM files; tls_ca set = TLS to the server, tls_cert + tls_key = the client
  // certificate the server requires for Connect when it has --tls-client-ca. token: a bearer token (role gateway).
  std::string tls_ca, tls_cert, tls_key, token;
  // Liveness (graspsim-gateway's systemd watchdog): called from the watchdog thread at each of its ticks while
  // every device thread has come round its loop within reading_period + stall_limit; never while one is stuck.
  std::function<void()> alive;
  std::chrono::milliseconds stall_limit{15000};  // above the longest device call (Robotiq activation: 5 s)
};

class GatewayClient {
 public:
  GatewayClient(GatewayOptions options, std::vector<std::unique_ptr<GuardedDevice>> devices);
  ~GatewayClient();
  // Connects, serves, reconnects until Shutdown(); returns after stopping every device.
  void Run();
  void Shutdown();  // any thread

 private:
  struct Worker;
  class Link;
  void Serve(Link& link);
  void Dispatch(const v1::DeviceCommand& command);
  void DeviceLoop(Worker& worker);
  void WatchdogLoop();
  // Stops every device; logs `why` and the time the stops took.
  void StopAll(const std::string& why, std::chrono::steady_clock::duration silent);
  void Send(const v1::GatewayMessage& message);

  const GatewayOptions options_;
  std::vector<std::unique_ptr<Worker>> workers_;
  std::atomic<bool> stop_{false};

  std::mutex link_mutex_;   // guards link_ (held only briefly: Shutdown cancels through it)
  std::mutex write_mutex_;  // serialises writes on the stream; the stream lives until no write holds it
  Link* link_ = nullptr;
  std::mutex wake_mutex_;
  std::condition_variable wake_;  // Shutdown during a backoff sleep

  // Watchdog: the time of the server's last message, and whether the link is up and not yet tripped.
  std::atomic<int64_t> last_rx_ns_{0};
  std::atomic<bool> armed_{false};
  std::thread watchdog_;
};

}  // namespace graspsim::drivers::gateway
