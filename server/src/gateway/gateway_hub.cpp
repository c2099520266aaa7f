#include "gateway/gateway_hub.h"

#include <cmath>

#include "core/error.h"
#include "core/format.h"
#include "core/log.h"

namespace graspsim::gateway {
namespace {

double UnixSeconds() {
  return std::chrono::duration<double>(std::chrono::system_clock::now().time_since_epoch()).count();
}

CommandResult Failure(uint64_t id, Code code, std::string message) {
  CommandResult result;
  result.command_id = id;
  result.code = code;
  result.message = std::move(message);
  return result;
}

}  // namespace

GatewayHub::GatewayHub() : GatewayHub(Options()) {}

GatewayHub::GatewayHub(Options options) : options_(options) {
  ticker_ = std::thread([this] {
    std::unique_lock<std::mutex> lock(mutex_);
    while (!stop_) {
      wake_.wait_for(lock, options_.heartbeat_interval);
      if (stop_) break;
      lock.unlock();
      Tick();
      lock.lock();
    }
  });
}

GatewayHub::~GatewayHub() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stop_ = true;
  }
  wake_.notify_all();
  ticker_.join();
  std::map<uint64_t, Pending> pending;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    pending.swap(pending_);
  }
  for (auto& [id, p] : pending) p.done(Failure(id, Code::kUnavailable, "the server is shutting down"));
}

void GatewayHub::Tick() {
  std::vector<std::pair<uint64_t, Pending>> expired;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    const double now_unix = UnixSeconds();
    for (auto& [id, session] : sessions_) session.sink->SendHeartbeat(now_unix);
    const auto now = std::chrono::steady_clock::now();
    for (auto it = pending_.begin(); it != pending_.end();) {
      if (it->second.deadline <= now) {
        expired.emplace_back(it->first, std::move(it->second));
        it = pending_.erase(it);
      } else {
        ++it;
      }
    }
  }
  for (auto& [id, p] : expired) {
    p.done(Failure(id, Code::kDeadlineExceeded,
                   "device '" + p.device_id + "': no result from its gateway for command " + std::to_string(id) +
                       " before the deadline"));
  }
}

uint64_t GatewayHub::Open(SessionSink* sink) {
  std::lock_guard<std::mutex> lock(mutex_);
  const uint64_t id = next_session_++;
  sessions_[id].sink = sink;
  return id;
}

void GatewayHub::Close(uint64_t session, const std::string& reason) {
  std::vector<std::pair<uint64_t, Pending>> failed;
  std::vector<std::string> removed;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    sessions_.erase(session);
    for (auto it = devices_.begin(); it != devices_.end();) {
      if (it->second.session == session) {
        removed.push_back(it->first);
        it = devices_.erase(it);
      } else {
        ++it;
      }
    }
    for (auto it = pending_.begin(); it != pending_.end();) {
      if (it->second.session == session) {
        failed.emplace_back(it->first, std::move(it->second));
        it = pending_.erase(it);
      } else {
        ++it;
      }
    }
  }
  for (const std::string& id : removed) Log(LogLevel::kInfo, "device gone", {{"device", id}, {"reason", reason}});
  for (auto& [id, p] : failed) {
    p.done(Failure(id, Code::kUnavailable,
                   "device '" + p.device_id + "': its gateway went away before answering: " + reason));
  }
}

void GatewayHub::EndAll(const std::string& reason) {
  std::lock_guard<std::mutex> lock(mutex_);
  for (auto& [id, session] : sessions_) session.sink->End(reason);
}

void GatewayHub::Register(uint64_t session, DeviceInfo device) {
  if (device.id.empty()) ThrowInvalidArgument("register_device.id: empty");
  if (device.kind.empty()) ThrowInvalidArgument("register_device.kind: empty (device '" + device.id + "')");
  if (device.gateway.empty()) ThrowInvalidArgument("register_device.gateway: empty (device '" + device.id + "')");
  const DeviceLimits& l = device.limits;
  if (!(l.min_opening >= 0 && l.max_opening > l.min_opening && l.min_speed >= 0 && l.max_speed > 0 &&
        l.min_force >= 0 && l.max_force > 0 && l.max_current > 0)) {
    ThrowInvalidArgument("register_device.limits: device '" + device.id + "' needs 0 <= min_opening < max_opening" +
                         " and positive max_speed, max_force and max_current");
  }
  std::lock_guard<std::mutex> lock(mutex_);
  const auto owner = sessions_.find(session);
  if (owner == sessions_.end()) throw Error(ErrorCode::kFailedPrecondition, "the gateway's session has ended");
  if (!owner->second.gateway.empty() && owner->second.gateway != device.gateway) {
    ThrowInvalidArgument("register_device.gateway: '" + device.gateway + "', but this stream is gateway '" +
                         owner->second.gateway + "'");
  }
  owner->second.gateway = device.gateway;
  if (const auto it = devices_.find(device.id); it != devices_.end() && it->second.session != session) {
    // A reconnecting gateway may register before the server noticed its old stream is dead.
    if (it->second.info.gateway != device.gateway) {
      throw Error(ErrorCode::kAlreadyExists, "register_device.id: '" + device.id + "' is already registered by gateway '" +
                                                 it->second.info.gateway + "'");
    }
  }
  Log(LogLevel::kInfo, "device registered", {{"device", device.id}, {"kind", device.kind}, {"gateway", device.gateway}});
  const std::string id = device.id;  // the right side of '=' is evaluated (and moved from) first
  devices_[id] = Entry{std::move(device), session};
}

void GatewayHub::OnReading(uint64_t session, const DeviceReading& reading) {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    const auto it = devices_.find(reading.device_id);
    if (it == devices_.end() || it->second.session != session) return;  // not (or no longer) this gateway's
    it->second.info.last_reading = reading;
  }
  Deliver(reading);
}

void GatewayHub::OnResult(uint64_t session, const CommandResult& result) {
  Pending p;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    const auto it = pending_.find(result.command_id);
    if (it == pending_.end() || it->second.session != session) {
      Log(LogLevel::kDebug, "late command result dropped", {{"command_id", std::to_string(result.command_id)}});
      return;
    }
    p = std::move(it->second);
    pending_.erase(it);
    if (result.reading) {
      if (const auto device = devices_.find(p.device_id); device != devices_.end()) {
        device->second.info.last_reading = *result.reading;
      }
    }
  }
  if (result.reading) Deliver(*result.reading);
  p.done(result);
}

void GatewayHub::Deliver(const DeviceReading& reading) {
  std::lock_guard<std::mutex> lock(subscriptions_mutex_);
  for (auto& [id, subscription] : subscriptions_) {
    if (subscription.first == reading.device_id) subscription.second(reading);
  }
}

std::vector<DeviceInfo> GatewayHub::Devices() const {
  std::lock_guard<std::mutex> lock(mutex_);
  std::vector<DeviceInfo> devices;
  for (const auto& [id, entry] : devices_) devices.push_back(entry.info);
  return devices;
}

std::optional<DeviceInfo> GatewayHub::Find(const std::string& device_id) const {
  std::lock_guard<std::mutex> lock(mutex_);
  const auto it = devices_.find(device_id);
  if (it == devices_.end()) return std::nullopt;
  return it->second.info;
}

uint64_t GatewayHub::Submit(Command command, Done done) {
  const double timeout = command.timeout == 0 ? options_.default_timeout_s : command.timeout;
  if (!(timeout > 0 && timeout <= options_.max_timeout_s)) {
    done(Failure(0, Code::kInvalidArgument, "timeout: " + FormatNumber(command.timeout) + " s is outside (0, " +
                                                FormatNumber(options_.max_timeout_s) + "]"));
    return 0;
  }
  std::unique_lock<std::mutex> lock(mutex_);
  const auto device = devices_.find(command.device_id);
  if (device == devices_.end()) {
    lock.unlock();
    done(Failure(0, Code::kNotFound, "device_id: no device '" + command.device_id + "' is registered"));
    return 0;
  }
  command.id = next_command_++;
  command.timeout = timeout;
  const uint64_t session = device->second.session;
  pending_[command.id] = Pending{session, command.device_id,
                                 std::chrono::steady_clock::now() +
                                     std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                                         std::chrono::duration<double>(timeout)),
                                 std::move(done)};
  sessions_.at(session).sink->SendCommand(command);
  return command.id;
}

void GatewayHub::EmergencyStop(const std::string& device_id, double timeout_s,
                               std::function<void(std::vector<std::pair<std::string, CommandResult>>)> done) {
  std::vector<std::string> ids;
  if (device_id.empty()) {
    for (const DeviceInfo& device : Devices()) ids.push_back(device.id);
  } else {
    ids.push_back(device_id);
  }
  struct Gather {
    std::mutex mutex;
    size_t left = 0;
    std::vector<std::pair<std::string, CommandResult>> results;
    std::function<void(std::vector<std::pair<std::string, CommandResult>>)> done;
  };
  auto gather = std::make_shared<Gather>();
  gather->left = ids.size();
  gather->done = std::move(done);
  if (ids.empty()) {
    gather->done({});
    return;
  }
  for (const std::string& id : ids) {
    Command command;
    command.device_id = id;
    command.kind = Command::Kind::kEstop;
    command.timeout = timeout_s;
    Submit(command, [gather, id](const CommandResult& result) {
      std::unique_lock<std::mutex> lock(gather->mutex);
      gather->results.emplace_back(id, result);
      if (--gather->left > 0) return;
      auto results = std::move(gather->results);
      lock.unlock();
      gather->done(std::move(results));
    });
  }
}

uint64_t GatewayHub::Subscribe(const std::string& device_id, ReadingCallback callback) {
  std::lock_guard<std::mutex> lock(subscriptions_mutex_);
  const uint64_t id = next_subscription_++;
  subscriptions_[id] = {device_id, std::move(callback)};
  return id;
}

void GatewayHub::Unsubscribe(uint64_t subscription) {
  std::lock_guard<std::mutex> lock(subscriptions_mutex_);
  subscriptions_.erase(subscription);
}

}  // namespace graspsim::gateway
