// sd_notify without libsystemd (drivers/tools/sd_notify.h): the datagrams reach a unix socket bound here, by path
// and in the abstract namespace, as systemd would receive them; the watchdog interval follows WATCHDOG_USEC and
// WATCHDOG_PID; pings are rate-limited; and GatewayClient's liveness hook, which drives the pings in
// graspsim-gateway, stops while a device thread is stuck in a call and resumes after.
#include "drivers/tools/sd_notify.h"

#include <sys/socket.h>
#include <sys/time.h>
#include <sys/un.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <chrono>
#include <cstddef>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <memory>
#include <string>
#include <thread>

#include <grpcpp/grpcpp.h>
#include <gtest/gtest.h>

#include "drivers/emulators/robotiq_emulator.h"
#include "drivers/gateway/device_spec.h"
#include "drivers/gateway/gateway_client.h"
#include "graspsim/v1/gateway.grpc.pb.h"
#include "rpc/server.h"

namespace graspsim {
namespace {

using namespace std::chrono_literals;
namespace sd = drivers::sdnotify;

// A datagram socket standing in for systemd's notify socket; restores the environment it changed.
class NotifySocket {
 public:
  // abstract: bound in the abstract namespace ("@name" in NOTIFY_SOCKET), else at a path in a fresh directory.
  explicit NotifySocket(bool abstract) {
    fd_ = socket(AF_UNIX, SOCK_DGRAM | SOCK_CLOEXEC, 0);
    EXPECT_GE(fd_, 0);
    const std::string unique = "graspsim-sd-notify-" + std::to_string(getpid()) + "-" + std::to_string(counter_++);
    sockaddr_un address{};
    address.sun_family = AF_UNIX;
    socklen_t length;
    if (abstract) {
      name_ = "@" + unique;
      address.sun_path[0] = '\0';
      std::memcpy(address.sun_path + 1, unique.data(), unique.size());
      length = static_cast<socklen_t>(offsetof(sockaddr_un, sun_path) + 1 + unique.size());
    } else {
      dir_ = std::filesystem::temp_directory_path() / unique;
      std::filesystem::create_directories(dir_);
      name_ = (dir_ / "notify").string();
      std::memcpy(address.sun_path, name_.data(), name_.size());
      length = static_cast<socklen_t>(offsetof(sockaddr_un, sun_path) + name_.size() + 1);
    }
    EXPECT_EQ(bind(fd_, reinterpret_cast<const sockaddr*>(&address), length), 0) << std::strerror(errno);
    timeval timeout{.tv_sec = 0, .tv_usec = 20000};
    setsockopt(fd_, SOL_SOCKET, SO_RCVTIMEO, &timeout, sizeof(timeout));
    setenv("NOTIFY_SOCKET", name_.c_str(), 1);
  }
  ~NotifySocket() {
    unsetenv("NOTIFY_SOCKET");
    close(fd_);
    if (!dir_.empty()) std::filesystem::remove_all(dir_);
  }
  // The next datagram, or "" after `wait`.
  std::string Receive(std::chrono::milliseconds wait = 2000ms) {
    const auto deadline = std::chrono::steady_clock::now() + wait;
    char buffer[4096];
    do {
      const ssize_t n = recv(fd_, buffer, sizeof(buffer), 0);
      if (n >= 0) return std::string(buffer, static_cast<size_t>(n));
    } while (std::chrono::steady_clock::now() < deadline);
    return "";
  }
  const std::string& name() const { return name_; }

 private:
  static inline int counter_ = 0;
  int fd_ = -1;
  std::string name_;
  std::filesystem::path dir_;
};

TEST(SdNotifyTest, SendsToASocketPath) {
  NotifySocket systemd(false);
  ASSERT_TRUE(sd::Notify("READY=1"));
  EXPECT_EQ(systemd.Receive(), "READY=1");
  ASSERT_TRUE(sd::Notify("STATUS=connected\nWATCHDOG=1"));
  EXPECT_EQ(systemd.Receive(), "STATUS=connected\nWATCHDOG=1");
}

TEST(SdNotifyTest, SendsToTheAbstractNamespace) {
  NotifySocket systemd(true);
  ASSERT_EQ(systemd.name()[0], '@');
  ASSERT_TRUE(sd::Notify("READY=1"));
  EXPECT_EQ(systemd.Receive(), "READY=1");
}

TEST(SdNotifyTest, DoesNothingOutsideSystemd) {
  unsetenv("NOTIFY_SOCKET");
  EXPECT_FALSE(sd::Notify("READY=1"));
  setenv("NOTIFY_SOCKET", "relative/path", 1);  // neither a path nor '@': refused, never sent anywhere
  EXPECT_FALSE(sd::Notify("READY=1"));
  setenv("NOTIFY_SOCKET", "/nonexistent/graspsim/notify", 1);
  EXPECT_FALSE(sd::Notify("READY=1"));
  unsetenv("NOTIFY_SOCKET");
}

TEST(SdNotifyTest, WatchdogIntervalIsOursOnlyForOurPid) {
  unsetenv("WATCHDOG_USEC");
  unsetenv("WATCHDOG_PID");
  EXPECT_EQ(sd::WatchdogInterval().count(), 0);
  setenv("WATCHDOG_USEC", "3000000", 1);
  EXPECT_EQ(sd::WatchdogInterval(), 3s);
  setenv("WATCHDOG_PID", std::to_string(getpid()).c_str(), 1);
  EXPECT_EQ(sd::WatchdogInterval(), 3s);
  setenv("WATCHDOG_PID", std::to_string(getpid() + 1).c_str(), 1);  // inherited from a parent: not ours
  EXPECT_EQ(sd::WatchdogInterval().count(), 0);
  unsetenv("WATCHDOG_PID");
  for (const char* bad : {"", "-5", "12x", "0", "abc"}) {
    setenv("WATCHDOG_USEC", bad, 1);
    EXPECT_EQ(sd::WatchdogInterval().count(), 0) << "WATCHDOG_USEC='" << bad << "'";
  }
  unsetenv("WATCHDOG_USEC");
}

TEST(SdNotifyTest, PingerSendsAtHalfTheInterval) {
  NotifySocket systemd(true);
  EXPECT_FALSE(sd::WatchdogPinger(0us).enabled());
  sd::WatchdogPinger pinger(400ms);  // a ping every 200 ms, however often Ping() is called
  const auto start = std::chrono::steady_clock::now();
  while (std::chrono::steady_clock::now() - start < 700ms) {
    pinger.Ping();
    std::this_thread::sleep_for(2ms);
  }
  int pings = 0;
  for (std::string message = systemd.Receive(50ms); !message.empty(); message = systemd.Receive(50ms)) {
    EXPECT_EQ(message, "WATCHDOG=1");
    ++pings;
  }
  EXPECT_GE(pings, 3);  // at 0, 200, 400 and 600 ms, less what a loaded machine delays
  EXPECT_LE(pings, 4);
}

// graspsim-gateway pings only through GatewayOptions::alive: it must stop while a device thread hangs in a call.
TEST(SdNotifyTest, GatewayLivenessStopsWhileADeviceCallHangs) {
  rpc::ServerOptions server_options;
  server_options.listen = "127.0.0.1:0";
  server_options.http_enabled = false;
  server_options.data_dir = "off";
  server_options.grasp_data_dir = "off";
  server_options.worker_threads = 2;
  rpc::GraspsimServer server(server_options);
  const std::string address = "127.0.0.1:" + std::to_string(server.port());
  auto emulator = drivers::emulators::RobotiqEmulator::StartTcp({});

  std::vector<std::unique_ptr<drivers::gateway::GuardedDevice>> devices;
  // A lost answer blocks the device thread for this long: the "hung call".
  devices.push_back(drivers::gateway::OpenDevice(
      drivers::gateway::ParseDeviceSpec("tcp=robotiq-tcp:127.0.0.1:" + std::to_string(emulator->port()), 0), "",
      2000ms));
  devices.back()->Initialize();
  std::atomic<int> alive{0};
  drivers::gateway::GatewayOptions options;
  options.server = address;
  options.name = "sd-notify";
  options.reading_period = 10ms;  // polls (only while connected) are what the lost answer hangs
  options.stall_limit = 100ms;
  options.alive = [&alive] { ++alive; };
  drivers::gateway::GatewayClient client(options, std::move(devices));
  std::thread runner([&client] { client.Run(); });

  auto stub = v1::GatewayService::NewStub(grpc::CreateChannel(address, grpc::InsecureChannelCredentials()));
  bool registered = false;
  for (auto deadline = std::chrono::steady_clock::now() + 20s; !registered && std::chrono::steady_clock::now() < deadline;) {
    grpc::ClientContext context;
    v1::ListDevicesResponse response;
    registered = stub->ListDevices(&context, {}, &response).ok() && response.devices_size() == 1;
    if (!registered) std::this_thread::sleep_for(20ms);
  }
  ASSERT_TRUE(registered);
  std::this_thread::sleep_for(300ms);
  const int before = alive.load();
  std::this_thread::sleep_for(300ms);
  EXPECT_GT(alive.load(), before) << "no liveness calls while every loop runs";

  emulator->InjectFault(drivers::emulators::ReplyFault::kNoReply);  // the next poll waits its 2 s for nothing
  std::this_thread::sleep_for(500ms);
  const int hung_start = alive.load();
  std::this_thread::sleep_for(900ms);
  EXPECT_EQ(alive.load(), hung_start) << "liveness reported while the device thread hung in a call";

  const auto deadline = std::chrono::steady_clock::now() + 10s;
  while (alive.load() == hung_start && std::chrono::steady_clock::now() < deadline) std::this_thread::sleep_for(20ms);
  EXPECT_GT(alive.load(), hung_start) << "liveness did not resume after the call returned";
  client.Shutdown();
  runner.join();
}

}  // namespace
}  // namespace graspsim
