// GatewayHub without gRPC: a recording sink stands for a gateway's stream.
#include "gateway/gateway_hub.h"

#include <chrono>
#include <thread>

#include <gtest/gtest.h>

#include "core/error.h"

namespace graspsim::gateway {
namespace {

struct RecordingSink : SessionSink {
  std::mutex mutex;
  std::vector<Command> commands;
  int heartbeats = 0;
  std::string ended;
  void SendCommand(const Command& command) override {
    std::lock_guard<std::mutex> lock(mutex);
    commands.push_back(command);
  }
  void SendHeartbeat(double) override {
    std::lock_guard<std::mutex> lock(mutex);
    ++heartbeats;
  }
  void End(const std::string& reason) override { ended = reason; }
};

DeviceInfo Device(const std::string& id, const std::string& gateway = "gw") {
  return {.id = id, .kind = "robotiq_2f85", .gateway = gateway, .link = "test",
          .limits = {.min_opening = 0, .max_opening = 0.085, .min_speed = 0.02, .max_speed = 0.15,
                     .min_force = 20, .max_force = 235, .max_current = 2.55}};
}

Command Read(const std::string& id, double timeout = 0) {
  Command command;
  command.device_id = id;
  command.kind = Command::Kind::kRead;
  command.timeout = timeout;
  return command;
}

TEST(GatewayHub, RelaysACommandAndItsResultById) {
  GatewayHub hub;
  RecordingSink sink;
  const uint64_t session = hub.Open(&sink);
  hub.Register(session, Device("d1"));
  std::optional<CommandResult> got;
  const uint64_t id = hub.Submit(Read("d1"), [&](const CommandResult& r) { got = r; });
  ASSERT_GT(id, 0u);
  ASSERT_EQ(sink.commands.size(), 1u);
  EXPECT_EQ(sink.commands[0].id, id);
  EXPECT_EQ(sink.commands[0].timeout, 5);  // the default
  EXPECT_FALSE(got);
  CommandResult other;
  other.command_id = id + 100;  // not pending: dropped
  hub.OnResult(session, other);
  EXPECT_FALSE(got);
  CommandResult result;
  result.command_id = id;
  result.reading = DeviceReading{.device_id = "d1", .time = 12, .opening = 0.04};
  hub.OnResult(session, result);
  ASSERT_TRUE(got);
  EXPECT_TRUE(got->ok());
  EXPECT_EQ(hub.Find("d1")->last_reading->opening, 0.04);  // the result's reading is the newest
  hub.Close(session, "test over");
}

TEST(GatewayHub, RefusesBadRegistrationsAndUnknownDevices) {
  GatewayHub hub;
  RecordingSink a, b;
  const uint64_t sa = hub.Open(&a), sb = hub.Open(&b);
  EXPECT_THROW(hub.Register(sa, Device("")), Error);
  DeviceInfo bad = Device("d1");
  bad.limits.max_opening = -1;
  EXPECT_THROW(hub.Register(sa, bad), Error);
  hub.Register(sa, Device("d1", "gw-a"));
  try {
    hub.Register(sb, Device("d1", "gw-b"));
    FAIL() << "a second gateway took over d1";
  } catch (const Error& error) {
    EXPECT_EQ(error.code(), ErrorCode::kAlreadyExists);
    EXPECT_NE(std::string(error.what()).find("gw-a"), std::string::npos) << error.what();
  }
  std::optional<CommandResult> got;
  EXPECT_EQ(hub.Submit(Read("nope"), [&](const CommandResult& r) { got = r; }), 0u);
  ASSERT_TRUE(got);
  EXPECT_EQ(got->code, Code::kNotFound);
  EXPECT_NE(got->message.find("'nope'"), std::string::npos);
  got.reset();
  hub.Submit(Read("d1", -1), [&](const CommandResult& r) { got = r; });
  EXPECT_EQ(got->code, Code::kInvalidArgument);
  EXPECT_TRUE(a.commands.empty());
}

TEST(GatewayHub, AReconnectingGatewayTakesItsDevicesOver) {
  GatewayHub hub;
  RecordingSink old_stream, new_stream;
  const uint64_t old_session = hub.Open(&old_stream);
  hub.Register(old_session, Device("d1"));
  const uint64_t new_session = hub.Open(&new_stream);
  hub.Register(new_session, Device("d1"));  // the same gateway before the old stream was noticed dead
  hub.Close(old_session, "old stream gone");
  ASSERT_TRUE(hub.Find("d1"));  // still there: it belongs to the new session now
  hub.Submit(Read("d1"), [](const CommandResult&) {});
  EXPECT_TRUE(old_stream.commands.empty());
  EXPECT_EQ(new_stream.commands.size(), 1u);
  hub.Close(new_session, "done");
  EXPECT_FALSE(hub.Find("d1"));
}

TEST(GatewayHub, PendingCommandsFailWhenTheGatewayGoesAwayOrTheDeadlinePasses) {
  GatewayHub hub(GatewayHub::Options{.heartbeat_interval = std::chrono::milliseconds(5)});
  RecordingSink sink;
  const uint64_t session = hub.Open(&sink);
  hub.Register(session, Device("d1"));
  std::atomic<int> code{-1};
  hub.Submit(Read("d1", 0.02), [&](const CommandResult& r) { code = static_cast<int>(r.code); });
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(10);
  while (code < 0 && std::chrono::steady_clock::now() < deadline) std::this_thread::sleep_for(std::chrono::milliseconds(1));
  EXPECT_EQ(code, static_cast<int>(Code::kDeadlineExceeded));
  {
    std::lock_guard<std::mutex> lock(sink.mutex);
    EXPECT_GT(sink.heartbeats, 0);
  }
  std::optional<CommandResult> got;
  hub.Submit(Read("d1"), [&](const CommandResult& r) { got = r; });
  hub.Close(session, "stream broke");
  ASSERT_TRUE(got);
  EXPECT_EQ(got->code, Code::kUnavailable);
  EXPECT_NE(got->message.find("stream broke"), std::string::npos);
}

TEST(GatewayHub, EmergencyStopGoesToEveryDeviceAndReportsEach) {
  GatewayHub hub;
  RecordingSink a, b;
  const uint64_t sa = hub.Open(&a), sb = hub.Open(&b);
  hub.Register(sa, Device("d1", "gw-a"));
  hub.Register(sb, Device("d2", "gw-b"));
  std::optional<std::vector<std::pair<std::string, CommandResult>>> got;
  hub.EmergencyStop("", 1, [&](auto results) { got = std::move(results); });
  ASSERT_EQ(a.commands.size(), 1u);
  ASSERT_EQ(b.commands.size(), 1u);
  EXPECT_EQ(a.commands[0].kind, Command::Kind::kEstop);
  CommandResult ok;
  ok.command_id = a.commands[0].id;
  hub.OnResult(sa, ok);
  EXPECT_FALSE(got);  // waits for both
  CommandResult failed;
  failed.command_id = b.commands[0].id;
  failed.code = Code::kUnavailable;
  failed.message = "no answer";
  hub.OnResult(sb, failed);
  ASSERT_TRUE(got);
  ASSERT_EQ(got->size(), 2u);
  hub.EndAll("shutdown");
  EXPECT_EQ(a.ended, "shutdown");
  hub.Close(sa, "");
  hub.Close(sb, "");
}

TEST(GatewayHub, SubscribersSeeTheirDevicesReadings) {
  GatewayHub hub;
  RecordingSink sink;
  const uint64_t session = hub.Open(&sink);
  hub.Register(session, Device("d1"));
  hub.Register(session, Device("d2"));
  std::vector<double> seen;
  const uint64_t subscription = hub.Subscribe("d1", [&](const DeviceReading& r) { seen.push_back(r.opening); });
  hub.OnReading(session, {.device_id = "d1", .opening = 0.01});
  hub.OnReading(session, {.device_id = "d2", .opening = 0.02});
  hub.OnReading(session + 1, {.device_id = "d1", .opening = 0.03});  // another session's: ignored
  hub.Unsubscribe(subscription);
  hub.OnReading(session, {.device_id = "d1", .opening = 0.04});
  EXPECT_EQ(seen, std::vector<double>{0.01});
  hub.Close(session, "");
}

}  // namespace
}  // namespace graspsim::gateway
