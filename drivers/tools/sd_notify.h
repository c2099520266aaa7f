// sd_notify(3) for graspsim-gateway without a libsystemd dependency: readiness and watchdog pings to systemd
// (deploy/systemd/graspsim-gateway.service, Type=notify, WatchdogSec=). Outside systemd ($NOTIFY_SOCKET unset)
// every call does nothing.
#pragma once

#include <atomic>
#include <chrono>
#include <cstdint>
#include <string_view>

namespace graspsim::drivers::sdnotify {

// Sends `state` (e.g. "READY=1", "WATCHDOG=1", "STATUS=...") as one datagram to the unix socket $NOTIFY_SOCKET
// names: a path, or '@' for the abstract namespace. false when the variable is unset or empty, or sending
// failed (errno set).
bool Notify(std::string_view state);

// How often systemd wants WATCHDOG=1: $WATCHDOG_USEC, when $WATCHDOG_PID is unset or names this process.
// Zero when the watchdog is off (or the variables are malformed).
std::chrono::microseconds WatchdogInterval();

// Sends WATCHDOG=1 at most every interval / 2 (sd_watchdog_enabled(3)'s advice), however often Ping() is
// called; the caller calls it only while its loops are alive, so a stuck process stops pinging.
class WatchdogPinger {
 public:
  explicit WatchdogPinger(std::chrono::microseconds interval);
  bool enabled() const { return half_.count() > 0; }
  void Ping();  // any thread

 private:
  const std::chrono::nanoseconds half_;
  std::atomic<int64_t> last_ns_{INT64_MIN};
};

}  // namespace graspsim::drivers::sdnotify
