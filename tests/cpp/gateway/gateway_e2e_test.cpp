// The gateway in one process, end to end through real gRPC: the server (GraspsimServer on a free port), a
// GatewayClient serving emulated grippers (Robotiq 2F-85 on Modbus TCP and on RTU over a pty pair, a PG70 on SMP
// over a socketpair), and a scripter's GatewayService stub. The emulators' fault injection checks that Modbus
// exceptions, lost answers and malformed frames reach the scripter as clear errors, with the device stopped.
#include <sys/socket.h>

#include <chrono>
#include <memory>
#include <thread>

#include <grpcpp/grpcpp.h>
#include <gtest/gtest.h>

#include "drivers/emulators/pg70_emulator.h"
#include "drivers/emulators/robotiq_emulator.h"
#include "drivers/gateway/device_spec.h"
#include "drivers/gateway/gateway_client.h"
#include "graspsim/v1/gateway.grpc.pb.h"
#include "rpc/server.h"

namespace graspsim {
namespace {

using drivers::emulators::Pg70Emulator;
using drivers::emulators::ReplyFault;
using drivers::emulators::RobotiqEmulator;
using namespace drivers::gateway;

class GatewayE2eTest : public ::testing::Test {
 protected:
  void SetUp() override {
    rpc::ServerOptions options;
    options.listen = "127.0.0.1:0";
    options.http_enabled = false;
    options.data_dir = "off";  // scenes in memory: never the user's store, and no test sees another's scenes
    options.grasp_data_dir = "off";
    options.worker_threads = 4;
    server_ = std::make_unique<rpc::GraspsimServer>(options);
    const std::string address = "127.0.0.1:" + std::to_string(server_->port());

    tcp_ = RobotiqEmulator::StartTcp({});
    rtu_ = RobotiqEmulator::StartRtu({});
    int fds[2];
    ASSERT_EQ(socketpair(AF_UNIX, SOCK_SEQPACKET, 0, fds), 0);
    pg70_ = std::make_unique<Pg70Emulator>(fds[1], Pg70Emulator::Options{});
    std::vector<std::unique_ptr<GuardedDevice>> devices;
    const std::string specs[] = {"tcp=robotiq-tcp:127.0.0.1:" + std::to_string(tcp_->port()),
                                 "rtu=robotiq-rtu:" + rtu_->device(), "pg=pg70-fd:" + std::to_string(fds[0])};
    for (int i = 0; i < 3; ++i) {
      devices.push_back(OpenDevice(ParseDeviceSpec(specs[i], i), "", std::chrono::milliseconds(200)));
      devices.back()->Initialize();
    }
    GatewayOptions gateway;
    gateway.server = address;
    gateway.name = "e2e";
    // No periodic polls: each injected fault must hit the command under test, not a poll.
    gateway.reading_period = std::chrono::hours(1);
    client_ = std::make_unique<GatewayClient>(gateway, std::move(devices));
    runner_ = std::thread([this] { client_->Run(); });

    stub_ = v1::GatewayService::NewStub(grpc::CreateChannel(address, grpc::InsecureChannelCredentials()));
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(20);
    while (std::chrono::steady_clock::now() < deadline) {
      grpc::ClientContext context;
      v1::ListDevicesResponse response;
      if (stub_->ListDevices(&context, {}, &response).ok() && response.devices_size() == 3) return;
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
    FAIL() << "the gateway's devices did not register";
  }
  void TearDown() override {
    client_->Shutdown();
    runner_.join();
    client_.reset();
    server_.reset();
  }

  grpc::Status Send(v1::DeviceCommand command, v1::CommandResult* result = nullptr) {
    grpc::ClientContext context;
    v1::CommandResult ignored;
    return stub_->SendCommand(&context, command, result ? result : &ignored);
  }
  static v1::DeviceCommand Move(const std::string& id, double opening, double speed) {
    v1::DeviceCommand command;
    command.set_device_id(id);
    command.mutable_move()->set_opening(opening);
    command.mutable_move()->set_speed(speed);
    command.mutable_move()->set_force(60);
    return command;
  }
  static v1::DeviceCommand Read(const std::string& id) {
    v1::DeviceCommand command;
    command.set_device_id(id);
    command.set_read(true);
    return command;
  }

  std::unique_ptr<rpc::GraspsimServer> server_;
  std::unique_ptr<RobotiqEmulator> tcp_, rtu_;
  std::unique_ptr<Pg70Emulator> pg70_;
  std::unique_ptr<GatewayClient> client_;
  std::thread runner_;
  std::unique_ptr<v1::GatewayService::Stub> stub_;
};

TEST_F(GatewayE2eTest, EveryCommandPathReachesTheEmulators) {
  v1::CommandResult result;
  ASSERT_TRUE(Send(Move("tcp", 0.0, 0.02), &result).ok());
  EXPECT_TRUE(result.ok());
  EXPECT_GT(result.command_id(), 0u);
  EXPECT_EQ(result.reading().device_id(), "tcp");
  EXPECT_TRUE(tcp_->command().rGTO);
  std::this_thread::sleep_for(std::chrono::milliseconds(100));
  EXPECT_TRUE(tcp_->moving());
  v1::DeviceCommand stop;
  stop.set_device_id("tcp");
  stop.set_stop(true);
  ASSERT_TRUE(Send(stop).ok());
  EXPECT_FALSE(tcp_->command().rGTO);

  ASSERT_TRUE(Send(Move("pg", 0.03, 0.05)).ok());
  EXPECT_TRUE(pg70_->moving());
  v1::DeviceCommand estop;
  estop.set_device_id("pg");
  estop.set_estop(true);
  ASSERT_TRUE(Send(estop, &result).ok());
  EXPECT_TRUE(result.reading().estopped());
  EXPECT_FALSE(pg70_->moving());
  const grpc::Status refused = Send(Move("pg", 0.03, 0.05));
  EXPECT_EQ(refused.error_code(), grpc::StatusCode::FAILED_PRECONDITION) << refused.error_message();

  v1::DeviceCommand speed, force, move_to;
  speed.set_device_id("rtu");
  speed.set_velocity(0.05);
  force.set_device_id("rtu");
  force.set_max_force(100);
  move_to.set_device_id("rtu");
  move_to.set_move_to(0.04);
  ASSERT_TRUE(Send(speed).ok());
  ASSERT_TRUE(Send(force).ok());
  ASSERT_TRUE(Send(move_to).ok());
  // The request registers say what the move_to sent: 40 mm at the speed and force set before.
  EXPECT_EQ(rtu_->command().rPR, drivers::robotiq::PositionCounts({}, 40.0));
  EXPECT_EQ(rtu_->command().rSP, drivers::robotiq::SpeedCounts({}, 50.0));
  EXPECT_EQ(rtu_->command().rFR, drivers::robotiq::ForceCounts({}, 100.0));
}

TEST_F(GatewayE2eTest, ModbusExceptionIsFailedPreconditionWithTheDeviceStopped) {
  for (auto* emulator : {tcp_.get(), rtu_.get()}) {
    const std::string id = emulator == tcp_.get() ? "tcp" : "rtu";
    ASSERT_TRUE(Send(Move(id, 0.0, 0.02)).ok());
    emulator->InjectFault(ReplyFault::kException, 1, 4);  // SERVER DEVICE FAILURE on the next request
    const grpc::Status status = Send(Read(id));
    EXPECT_EQ(status.error_code(), grpc::StatusCode::FAILED_PRECONDITION) << id << ": " << status.error_message();
    EXPECT_NE(status.error_message().find("device '" + id + "'"), std::string::npos) << status.error_message();
    EXPECT_NE(status.error_message().find("stop sent"), std::string::npos) << status.error_message();
    EXPECT_FALSE(emulator->command().rGTO) << id;
    EXPECT_TRUE(Send(Read(id)).ok()) << id;  // the link recovers
  }
}

TEST_F(GatewayE2eTest, LostOrMalformedAnswersAreUnavailableWithTheDeviceStopped) {
  struct Case {
    const char* id;
    std::function<void()> inject;
    std::function<bool()> moving;
  };
  const Case cases[] = {
      {"tcp", [&] { tcp_->InjectFault(ReplyFault::kNoReply); }, [&] { return tcp_->command().rGTO; }},
      {"rtu", [&] { rtu_->InjectFault(ReplyFault::kBadCrc); }, [&] { return rtu_->command().rGTO; }},
      {"rtu", [&] { rtu_->InjectFault(ReplyFault::kTruncated); }, [&] { return rtu_->command().rGTO; }},
      {"pg", [&] { pg70_->InjectFault(Pg70Emulator::Fault::kMalformed); }, [&] { return pg70_->moving(); }},
      {"pg", [&] { pg70_->InjectFault(Pg70Emulator::Fault::kSilent); }, [&] { return pg70_->moving(); }},
  };
  for (const Case& c : cases) {
    ASSERT_TRUE(Send(Move(c.id, 0.0, 0.02)).ok()) << c.id;
    c.inject();
    const grpc::Status status = Send(Read(c.id));
    EXPECT_EQ(status.error_code(), grpc::StatusCode::UNAVAILABLE) << c.id << ": " << status.error_message();
    EXPECT_NE(status.error_message().find("stop sent"), std::string::npos) << status.error_message();
    EXPECT_FALSE(c.moving()) << c.id;
    EXPECT_TRUE(Send(Read(c.id)).ok()) << c.id;
  }
}

TEST_F(GatewayE2eTest, Pg70ErrorMessageIsFailedPrecondition) {
  ASSERT_TRUE(Send(Move("pg", 0.01, 0.02)).ok());
  pg70_->InjectFault(Pg70Emulator::Fault::kErrorMessage, 1, drivers::pg70::smp::kErrorOverCurrent);
  const grpc::Status status = Send(Read("pg"));
  EXPECT_EQ(status.error_code(), grpc::StatusCode::FAILED_PRECONDITION) << status.error_message();
  EXPECT_NE(status.error_message().find("error"), std::string::npos) << status.error_message();
  EXPECT_FALSE(pg70_->moving());
}

TEST_F(GatewayE2eTest, ServerShutdownStopsTheDevices) {
  ASSERT_TRUE(Send(Move("tcp", 0.0, 0.02)).ok());
  ASSERT_TRUE(Send(Move("pg", 0.0, 0.02)).ok());
  server_->Shutdown();  // ends the gateway's stream: the gateway stops everything at once
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(10);
  while ((tcp_->command().rGTO || pg70_->moving()) && std::chrono::steady_clock::now() < deadline) {
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  EXPECT_FALSE(tcp_->command().rGTO);
  EXPECT_FALSE(pg70_->moving());
  EXPECT_GT(tcp_->opening_mm(), 30.0);  // stopped long before closing (85 mm at 20 mm/s)
}

}  // namespace
}  // namespace graspsim
