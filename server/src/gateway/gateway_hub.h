// The server's side of the hardware gateways: which gateway owns which device, the commands in flight to them
// (each with an id and a deadline), their newest readings, and the heartbeats that keep each gateway's watchdog
// fed. One GatewayHub per server; sessions are the gateways' Connect streams, seen through a SessionSink.
//
// Threads: every method may be called from any thread. A ticker thread sends heartbeats every
// heartbeat_interval and fails commands whose deadline passed. Sink methods are called with the hub's lock
// held (they must only queue, never call back into the hub); completion and reading callbacks run without it.
#pragma once

#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "gateway/gateway_types.h"

namespace graspsim::gateway {

// The outgoing half of one gateway's stream.
class SessionSink {
 public:
  virtual ~SessionSink() = default;
  virtual void SendCommand(const Command& command) = 0;
  virtual void SendHeartbeat(double time) = 0;
  // Ends the stream (server shutdown); the stream then closes its session as usual.
  virtual void End(const std::string& reason) = 0;
};

class GatewayHub {
 public:
  struct Options {
    std::chrono::milliseconds heartbeat_interval{50};
    double default_timeout_s = 5;
    double max_timeout_s = 60;
  };
  using Done = std::function<void(const CommandResult&)>;
  using ReadingCallback = std::function<void(const DeviceReading&)>;

  GatewayHub();
  explicit GatewayHub(Options options);
  ~GatewayHub();
  GatewayHub(const GatewayHub&) = delete;
  GatewayHub& operator=(const GatewayHub&) = delete;

  // A gateway's stream opened: returns its session id. The sink stays in use until Close(session).
  uint64_t Open(SessionSink* sink);
  // The gateway's stream ended: its devices leave the registry and its commands in flight fail (UNAVAILABLE).
  void Close(uint64_t session, const std::string& reason);
  // Ends every gateway's stream (server shutdown: they would hold the drain open).
  void EndAll(const std::string& reason);
  // Throws Error(kInvalidArgument) for an empty id, kind or gateway and kAlreadyExists for an id another live
  // gateway holds. The same gateway re-registering (after a reconnection) replaces its old session's entry.
  void Register(uint64_t session, DeviceInfo device);
  void OnReading(uint64_t session, const DeviceReading& reading);
  void OnResult(uint64_t session, const CommandResult& result);

  std::vector<DeviceInfo> Devices() const;
  std::optional<DeviceInfo> Find(const std::string& device_id) const;
  // Relays `command` to its device's gateway. `done` is called exactly once: with the gateway's result, or
  // NOT_FOUND (no such device), INVALID_ARGUMENT (a bad timeout), DEADLINE_EXCEEDED (no result in time) or
  // UNAVAILABLE (the gateway went away). May be called before Submit returns. Returns the command id (0 when
  // refused at once).
  uint64_t Submit(Command command, Done done);
  // E-stop of one device or (empty id) all: `done` gets, per device, the result of its gateway's stop.
  void EmergencyStop(const std::string& device_id, double timeout_s,
                     std::function<void(std::vector<std::pair<std::string, CommandResult>>)> done);

  // Readings of one device as they arrive, until Unsubscribe (which waits for a callback in progress).
  uint64_t Subscribe(const std::string& device_id, ReadingCallback callback);
  void Unsubscribe(uint64_t subscription);

 private:
  struct Session {
    SessionSink* sink = nullptr;
    std::string gateway;
  };
  struct Pending {
    uint64_t session = 0;
    std::string device_id;
    std::chrono::steady_clock::time_point deadline;
    Done done;
  };
  struct Entry {
    DeviceInfo info;
    uint64_t session = 0;
  };
  void Tick();
  void Deliver(const DeviceReading& reading);

  const Options options_;
  mutable std::mutex mutex_;
  std::map<uint64_t, Session> sessions_;
  std::map<std::string, Entry> devices_;
  std::map<uint64_t, Pending> pending_;
  uint64_t next_session_ = 1, next_command_ = 1;

  std::mutex subscriptions_mutex_;  // held while callbacks run, so Unsubscribe waits for them
  std::map<uint64_t, std::pair<std::string, ReadingCallback>> subscriptions_;
  uint64_t next_subscription_ = 1;

  std::condition_variable wake_;
  bool stop_ = false;
  std::thread ticker_;
};

}  // namespace graspsim::gateway
