#include "drivers/gateway/gateway_client.h"

#include <grpcpp/grpcpp.h>

#include <cstdio>
#include <fstream>
#include <sstream>
#include <optional>

#include "core/error.h"
#include "core/log.h"
#include "drivers/common/device_error.h"
#include "graspsim/v1/gateway.grpc.pb.h"

namespace graspsim::drivers::gateway {
namespace {

using Clock = std::chrono::steady_clock;

int64_t NowNs() { return std::chrono::duration_cast<std::chrono::nanoseconds>(Clock::now().time_since_epoch()).count(); }

double UnixSeconds() {
  return std::chrono::duration<double>(std::chrono::system_clock::now().time_since_epoch()).count();
}

std::string Ms(Clock::duration d) {
  char text[32];
  std::snprintf(text, sizeof(text), "%.1f", std::chrono::duration<double, std::milli>(d).count());
  return text;
}

void ToProto(const GuardedDevice& device, const GripperReading& r, v1::DeviceReading* out) {
  out->set_device_id(device.id());
  out->set_time(UnixSeconds());
  out->set_opening(r.opening_m);
  out->set_current(r.current_a);
  out->set_moving(r.moving);
  out->set_object_detected(r.object_detected);
  out->set_fault(r.fault);
  out->set_estopped(device.estopped());
}

// grpc status codes (the numbers the server passes on): a refused value, a device that cannot do it now, a link
// that does not answer.
int CodeOf(const Error& error) {
  if (const auto* device = dynamic_cast<const DeviceError*>(&error)) {
    switch (device->failure()) {
      case DeviceFailure::kTimeout:
      case DeviceFailure::kIo:
      case DeviceFailure::kMalformedFrame:
        return grpc::StatusCode::UNAVAILABLE;
      case DeviceFailure::kDeviceException:
      case DeviceFailure::kDeviceFault:
        return grpc::StatusCode::FAILED_PRECONDITION;
    }
  }
  switch (error.code()) {
    case ErrorCode::kInvalidArgument: return grpc::StatusCode::INVALID_ARGUMENT;
    case ErrorCode::kNotFound: return grpc::StatusCode::NOT_FOUND;
    case ErrorCode::kFailedPrecondition: return grpc::StatusCode::FAILED_PRECONDITION;
    default: return grpc::StatusCode::INTERNAL;
  }
}

}  // namespace

struct GatewayClient::Worker {
  std::unique_ptr<GuardedDevice> device;
  std::mutex mutex;
  std::condition_variable wake;
  std::deque<v1::DeviceCommand> queue;
  std::string last_error;  // of the last failed poll: logged once, not at every period
  std::atomic<int64_t> loop_ns{NowNs()};  // when the thread last came round its loop (options.alive)
  std::thread thread;
};

namespace {

std::string ReadPem(const std::string& flag, const std::string& path) {
  std::ifstream file(path, std::ios::binary);
  if (!file) ThrowInvalidArgument("--" + flag + ": cannot read '" + path + "'");
  std::ostringstream text;
  text << file.rdbuf();
  return text.str();
}

// TLS when a CA is given (with the client certificate, if any); plaintext otherwise, for loopback servers.
std::shared_ptr<grpc::ChannelCredentials> ChannelCredentials(const GatewayOptions& options) {
  if (options.tls_ca.empty()) return grpc::InsecureChannelCredentials();
  grpc::SslCredentialsOptions ssl;
  ssl.pem_root_certs = ReadPem("tls-ca", options.tls_ca);
  if (!options.tls_cert.empty()) {
    ssl.pem_cert_chain = ReadPem("tls-cert", options.tls_cert);
    ssl.pem_private_key = ReadPem("tls-key", options.tls_key);
  }
  return grpc::SslCredentials(ssl);
}

}  // namespace

class GatewayClient::Link {
 public:
  Link(v1::GatewayService::Stub* stub, const std::string& token) {
    if (!token.empty()) context.AddMetadata("authorization", "Bearer " + token);
    stream = stub->Connect(&context);
  }
  grpc::ClientContext context;
  std::unique_ptr<grpc::ClientReaderWriter<v1::GatewayMessage, v1::GatewayCommand>> stream;
  bool broken = false;
};

GatewayClient::GatewayClient(GatewayOptions options, std::vector<std::unique_ptr<GuardedDevice>> devices)
    : options_(std::move(options)) {
  for (auto& device : devices) {
    auto worker = std::make_unique<Worker>();
    worker->device = std::move(device);
    workers_.push_back(std::move(worker));
  }
  for (auto& worker : workers_) worker->thread = std::thread([this, w = worker.get()] { DeviceLoop(*w); });
  watchdog_ = std::thread([this] { WatchdogLoop(); });
}

GatewayClient::~GatewayClient() {
  Shutdown();
  for (auto& worker : workers_) {
    worker->wake.notify_all();
    worker->thread.join();
  }
  watchdog_.join();
}

void GatewayClient::Shutdown() {
  stop_ = true;
  {
    std::lock_guard<std::mutex> lock(link_mutex_);
    if (link_ != nullptr) link_->context.TryCancel();
  }
  std::lock_guard<std::mutex> lock(wake_mutex_);
  wake_.notify_all();
}

void GatewayClient::Run() {
  // The channel's own reconnection backoff (default: 1 s growing to 120 s) would keep failing calls fast long
  // after the server is back; it follows this gateway's backoff instead.
  grpc::ChannelArguments arguments;
  arguments.SetInt(GRPC_ARG_INITIAL_RECONNECT_BACKOFF_MS, static_cast<int>(options_.backoff_initial.count()));
  arguments.SetInt(GRPC_ARG_MIN_RECONNECT_BACKOFF_MS, static_cast<int>(options_.backoff_initial.count()));
  arguments.SetInt(GRPC_ARG_MAX_RECONNECT_BACKOFF_MS, static_cast<int>(options_.backoff_max.count()));
  auto channel = grpc::CreateCustomChannel(options_.server, ChannelCredentials(options_), arguments);
  auto stub = v1::GatewayService::NewStub(channel);
  auto backoff = options_.backoff_initial;
  while (!stop_) {
    // Waiting for the connection (rather than failing fast) is the backoff's sleep while the server is away.
    if (!channel->WaitForConnected(std::chrono::system_clock::now() + backoff)) {
      Log(LogLevel::kDebug, "server not reachable", {{"server", options_.server}, {"waited_ms", std::to_string(backoff.count())}});
      backoff = std::min(backoff * 2, options_.backoff_max);
      continue;
    }
    const int64_t before = last_rx_ns_.load();
    {
      Link link(stub.get(), options_.token);
      {
        std::lock_guard<std::mutex> lock(link_mutex_);
        link_ = &link;
        if (stop_) link.context.TryCancel();
      }
      Serve(link);
      {
        // Not cancelled here: the server's status (e.g. a refused registration) is what Finish reports.
        std::lock_guard<std::mutex> lock(link_mutex_);
        link_ = nullptr;
      }
      { std::lock_guard<std::mutex> wait_for_writers(write_mutex_); }
      const grpc::Status status = link.stream->Finish();
      if (!stop_) {
        Log(LogLevel::kWarn, "link to the server ended",
            {{"server", options_.server}, {"code", std::to_string(status.error_code())}, {"error", status.error_message()}});
      }
    }
    for (auto& worker : workers_) {  // the server failed the commands in flight when the stream ended
      std::lock_guard<std::mutex> lock(worker->mutex);
      worker->queue.clear();
    }
    if (stop_) break;
    if (last_rx_ns_.load() != before) backoff = options_.backoff_initial;  // that session worked: start over
    Log(LogLevel::kInfo, "reconnecting", {{"server", options_.server}, {"in_ms", std::to_string(backoff.count())}});
    std::unique_lock<std::mutex> lock(wake_mutex_);
    wake_.wait_for(lock, backoff, [this] { return stop_.load(); });
    backoff = std::min(backoff * 2, options_.backoff_max);
  }
  StopAll("the gateway is shutting down", {});
}

void GatewayClient::Serve(Link& link) {
  for (const auto& worker : workers_) {
    const GuardedDevice& device = *worker->device;
    v1::GatewayMessage message;
    v1::Device* info = message.mutable_register_device();
    info->set_id(device.id());
    info->set_kind(device.kind());
    info->set_gateway(options_.name);
    info->set_link(device.link());
    const Limits& l = device.limits();
    v1::DeviceLimits* limits = info->mutable_limits();
    limits->set_min_opening(l.min_opening);
    limits->set_max_opening(l.max_opening);
    limits->set_min_speed(l.min_speed);
    limits->set_max_speed(l.max_speed);
    limits->set_min_force(l.min_force);
    limits->set_max_force(l.max_force);
    limits->set_max_current(l.max_current);
    std::lock_guard<std::mutex> lock(write_mutex_);
    if (!link.stream->Write(message)) return;
  }
  v1::GatewayCommand in;
  bool first = true;
  while (link.stream->Read(&in)) {
    last_rx_ns_ = NowNs();
    if (first) {
      Log(LogLevel::kInfo, "connected", {{"server", options_.server}, {"devices", std::to_string(workers_.size())}});
      first = false;
    }
    armed_ = true;  // (re)arms the watchdog
    if (in.has_command()) Dispatch(in.command());
  }
  // The stream is gone: nobody can command or watch the devices any more.
  const bool was_armed = armed_.exchange(false);
  if (was_armed) StopAll("the link to the server ended", Clock::now() - Clock::time_point(std::chrono::nanoseconds(last_rx_ns_.load())));
}

void GatewayClient::Dispatch(const v1::DeviceCommand& command) {
  for (auto& worker : workers_) {
    if (worker->device->id() != command.device_id()) continue;
    {
      std::lock_guard<std::mutex> lock(worker->mutex);
      if (command.has_stop() || command.has_estop()) {
        // A stop must not wait behind moves: they are dropped, and the server times them out.
        worker->queue.clear();
        worker->queue.push_front(command);
      } else {
        worker->queue.push_back(command);
      }
    }
    worker->wake.notify_one();
    return;
  }
  v1::GatewayMessage message;
  v1::CommandResult* result = message.mutable_result();
  result->set_command_id(command.command_id());
  result->set_code(grpc::StatusCode::NOT_FOUND);
  result->set_message("device_id: gateway '" + options_.name + "' has no device '" + command.device_id() + "'");
  Send(message);
}

void GatewayClient::DeviceLoop(Worker& worker) {
  GuardedDevice& device = *worker.device;
  auto next_poll = Clock::now();
  while (!stop_) {
    worker.loop_ns = NowNs();
    std::optional<v1::DeviceCommand> command;
    {
      std::unique_lock<std::mutex> lock(worker.mutex);
      worker.wake.wait_until(lock, next_poll, [&] { return stop_ || !worker.queue.empty(); });
      if (stop_) return;
      if (!worker.queue.empty()) {
        command = std::move(worker.queue.front());
        worker.queue.pop_front();
      }
    }
    if (!command) {
      next_poll = Clock::now() + options_.reading_period;
      if (!armed_) continue;  // nobody listens: leave the link to the device quiet
      v1::GatewayMessage message;
      try {
        ToProto(device, device.Read(), message.mutable_device_reading());
        worker.last_error.clear();
      } catch (const Error& error) {
        if (worker.last_error != error.what()) Log(LogLevel::kWarn, "reading failed", {{"device", device.id()}, {"error", error.what()}});
        worker.last_error = error.what();
        continue;
      }
      Send(message);
      continue;
    }
    const auto start = Clock::now();
    v1::GatewayMessage message;
    v1::CommandResult* result = message.mutable_result();
    result->set_command_id(command->command_id());
    try {
      switch (command->command_case()) {
        case v1::DeviceCommand::kMoveTo: device.MoveTo(command->move_to()); break;
        case v1::DeviceCommand::kVelocity: device.SetSpeed(command->velocity()); break;
        case v1::DeviceCommand::kMaxForce: device.SetForce(command->max_force()); break;
        case v1::DeviceCommand::kStop: device.Stop(); break;
        case v1::DeviceCommand::kInitialize: device.Initialize(); break;
        case v1::DeviceCommand::kEstop: device.EmergencyStop(); break;
        case v1::DeviceCommand::kMove:
          device.Move(command->move().opening(), command->move().speed(), command->move().force());
          break;
        case v1::DeviceCommand::kRead: break;
        case v1::DeviceCommand::COMMAND_NOT_SET: ThrowInvalidArgument("command: none set");
      }
      ToProto(device, device.Read(), result->mutable_reading());
      result->set_ok(true);
    } catch (const Error& error) {
      result->set_ok(false);
      result->set_code(CodeOf(error));
      result->set_message("device '" + device.id() + "': " + error.what());
      Log(LogLevel::kWarn, "command failed", {{"device", device.id()}, {"error", error.what()}});
    }
    result->set_gateway_seconds(std::chrono::duration<double>(Clock::now() - start).count());
    Send(message);
  }
}

void GatewayClient::WatchdogLoop() {
  const auto period = std::max(std::chrono::milliseconds(1), options_.watchdog / 20);
  while (!stop_) {
    std::this_thread::sleep_for(period);
    if (options_.alive) {
      const int64_t limit = std::chrono::nanoseconds(options_.reading_period + options_.stall_limit).count();
      bool stuck = false;
      for (const auto& worker : workers_) stuck = stuck || NowNs() - worker->loop_ns.load() > limit;
      if (!stuck) options_.alive();
    }
    if (!armed_) continue;
    const auto silent = std::chrono::nanoseconds(NowNs() - last_rx_ns_.load());
    if (silent <= options_.watchdog) continue;
    if (!armed_.exchange(false)) continue;  // the reader disarmed it meanwhile (and stopped the devices)
    StopAll("watchdog: the server has been silent for longer than " + std::to_string(options_.watchdog.count()) + " ms",
            silent);
  }
}

void GatewayClient::StopAll(const std::string& why, Clock::duration silent) {
  const auto start = Clock::now();
  int stopped = 0;
  for (auto& worker : workers_) {
    try {
      worker->device->Stop();
      ++stopped;
    } catch (const Error& error) {
      Log(LogLevel::kError, "stop failed", {{"device", worker->device->id()}, {"error", error.what()}});
    }
  }
  char unix_time[32];
  std::snprintf(unix_time, sizeof(unix_time), "%.6f", UnixSeconds());
  Log(LogLevel::kWarn, "devices stopped", {{"why", why}, {"stopped", std::to_string(stopped)},
                                           {"silent_ms", Ms(silent)}, {"stop_ms", Ms(Clock::now() - start)},
                                           {"unix", unix_time}});
}

void GatewayClient::Send(const v1::GatewayMessage& message) {
  std::lock_guard<std::mutex> write(write_mutex_);
  Link* link = nullptr;
  {
    std::lock_guard<std::mutex> lock(link_mutex_);
    link = link_;
  }
  if (link == nullptr || link->broken) return;
  if (!link->stream->Write(message)) link->broken = true;
}

}  // namespace graspsim::drivers::gateway
