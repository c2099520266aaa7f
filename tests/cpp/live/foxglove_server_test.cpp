// The Foxglove WebSocket server against a real Beast client on a free port: handshake and subprotocol, advertise,
// subscriptions and the binary message layout, bad input, the producer's lifetime, and a client that never reads.
#include "live/foxglove_server.h"

#include <atomic>
#include <chrono>
#include <functional>
#include <mutex>
#include <thread>

#include <boost/asio/ip/tcp.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/http.hpp>
#include <boost/beast/websocket.hpp>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "core/error.h"
#include "test_util.h"

namespace graspsim::live {
namespace {

namespace asio = boost::asio;
namespace beast = boost::beast;
namespace websocket = beast::websocket;
using nlohmann::json;
using namespace std::chrono_literals;

const std::string kDescriptorSet("\x0a\x00\xff\x10", 4);  // binary, as a FileDescriptorSet is

// Deadlines here only stop a broken test from hanging; no test asserts on time.
bool WaitFor(const std::function<bool()>& condition) {
  for (int i = 0; i < 1000 && !condition(); ++i) std::this_thread::sleep_for(10ms);
  return condition();
}

std::string Payload(uint64_t t) { return std::string("\0\xff", 2) + "msg " + std::to_string(t); }

uint64_t LittleEndian(const std::string& bytes, size_t at, size_t size) {
  uint64_t value = 0;
  for (size_t i = 0; i < size; ++i) value |= uint64_t{static_cast<unsigned char>(bytes[at + i])} << (8 * i);
  return value;
}

// What on_open returns: advertises two channels, then streams channel 1 from its own thread while subscribed.
class Producer {
 public:
  Producer(std::shared_ptr<Connection> connection, std::atomic<int>* destroyed) : destroyed_(destroyed) {
    connection->Advertise({{1, "/tf", "protobuf", "foxglove.FrameTransforms", "protobuf", kDescriptorSet},
                           {2, "/note", "json", "Note", "jsonschema", R"({"type":"object"})"}});
    thread_ = std::thread([this, connection] {
      for (uint64_t t = 1; !stop_; std::this_thread::sleep_for(1ms)) {
        if (!connection->HasSubscribers(1)) continue;
        connection->SendMessage(1, t, Payload(t));
        ++t;
      }
    });
  }
  ~Producer() {
    stop_ = true;
    thread_.join();
    ++*destroyed_;
  }

 private:
  std::atomic<int>* destroyed_;
  std::atomic<bool> stop_{false};
  std::thread thread_;
};

struct Message {
  bool text = false;
  std::string data;
};

class Client {
 public:
  explicit Client(int port, const std::string& target = "/") : ws_(ioc_) {
    beast::get_lowest_layer(ws_).connect(asio::ip::tcp::endpoint(asio::ip::make_address("127.0.0.1"), port));
    ws_.set_option(websocket::stream_base::decorator([](websocket::request_type& request) {
      request.set(beast::http::field::sec_websocket_protocol, "other.v2, foxglove.websocket.v1");
    }));
    ws_.handshake(response_, "127.0.0.1", target, handshake_error_);
  }
  const websocket::response_type& response() const { return response_; }
  beast::error_code handshake_error() const { return handshake_error_; }

  void Send(const std::string& text) { ws_.write(asio::buffer(text)); }
  // Throws (failing the test) when the connection fails or nothing comes for a long while.
  Message Read() {
    beast::flat_buffer buffer;
    bool done = false;
    beast::error_code error;
    ws_.async_read(buffer, [&](beast::error_code ec, size_t) {
      done = true;
      error = ec;
    });
    ioc_.restart();
    ioc_.run_for(10s);
    if (!done) {
      Drop();  // ends the read, which refers to locals of this frame
      ioc_.restart();
      ioc_.run();
      throw std::runtime_error("no message from the server");
    }
    if (error) throw std::runtime_error("read: " + error.message());
    return {ws_.got_text(), beast::buffers_to_string(buffer.data())};
  }
  json ReadJson() {
    const Message message = Read();
    EXPECT_TRUE(message.text);
    return json::parse(message.data, nullptr, false);
  }
  void Close() { ws_.close(websocket::close_code::normal); }
  void Drop() { beast::get_lowest_layer(ws_).close(); }  // no close handshake: an abrupt disconnect

 private:
  asio::io_context ioc_;
  websocket::stream<beast::tcp_stream> ws_;
  websocket::response_type response_;
  beast::error_code handshake_error_;
};

// An upgrade request by hand: Beast's client handshake does not hand back a refused response.
beast::http::status UpgradeWithout(int port) {
  asio::io_context ioc;
  beast::tcp_stream stream(ioc);
  stream.connect(asio::ip::tcp::endpoint(asio::ip::make_address("127.0.0.1"), port));
  beast::http::request<beast::http::empty_body> request(beast::http::verb::get, "/", 11);
  request.set(beast::http::field::host, "127.0.0.1");
  request.set(beast::http::field::upgrade, "websocket");
  request.set(beast::http::field::connection, "upgrade");
  request.set(beast::http::field::sec_websocket_key, "dGhlIHNhbXBsZSBub25jZQ==");
  request.set(beast::http::field::sec_websocket_version, "13");
  beast::http::write(stream, request);
  beast::flat_buffer buffer;
  beast::http::response<beast::http::string_body> response;
  beast::http::read(stream, buffer, response);
  return response.result();
}

class FoxgloveServerTest : public ::testing::Test {
 protected:
  std::unique_ptr<FoxgloveServer> Start(size_t max_queued_bytes = 8 << 20) {
    FoxgloveServerOptions options;
    options.listen = "127.0.0.1:0";
    options.name = "graspsim-test";
    options.max_queued_bytes = max_queued_bytes;
    return std::make_unique<FoxgloveServer>(options, [this](std::shared_ptr<Connection> connection) {
      std::lock_guard lock(mu_);
      connection_ = connection;
      return std::make_shared<Producer>(connection, &destroyed_);
    });
  }
  std::shared_ptr<Connection> connection() {
    std::lock_guard lock(mu_);
    return connection_;
  }
  // Reads past the server's reply to an op it does not know, which it sends after handling all that came before.
  static std::vector<Message> ReadUntilStatus(Client& client) {
    client.Send(R"({"op":"noSuchOp"})");
    std::vector<Message> before;
    for (Message m = client.Read(); !m.text || json::parse(m.data)["op"] != "status"; m = client.Read()) {
      before.push_back(m);
    }
    return before;
  }

  std::atomic<int> destroyed_{0};
  std::mutex mu_;
  std::shared_ptr<Connection> connection_;
};

TEST_F(FoxgloveServerTest, HandshakeServerInfoAndAdvertise) {
  auto server = Start();
  ASSERT_GT(server->port(), 0);
  Client client(server->port(), "/scene-42?x=1");
  ASSERT_FALSE(client.handshake_error()) << client.handshake_error().message();
  EXPECT_EQ(client.response()[beast::http::field::sec_websocket_protocol], "foxglove.websocket.v1");

  const json info = client.ReadJson();
  EXPECT_EQ(info["op"], "serverInfo");
  EXPECT_EQ(info["name"], "graspsim-test");
  EXPECT_EQ(info["capabilities"], json::array());
  EXPECT_TRUE(info["sessionId"].is_string() && !info["sessionId"].get<std::string>().empty());

  const json advertise = client.ReadJson();
  EXPECT_EQ(advertise["op"], "advertise");
  ASSERT_EQ(advertise["channels"].size(), 2u);
  const json& tf = advertise["channels"][0];
  EXPECT_EQ(tf["id"], 1);
  EXPECT_EQ(tf["topic"], "/tf");
  EXPECT_EQ(tf["encoding"], "protobuf");
  EXPECT_EQ(tf["schemaName"], "foxglove.FrameTransforms");
  EXPECT_EQ(tf["schemaEncoding"], "protobuf");
  EXPECT_EQ(tf["schema"], "CgD/EA==");  // base64 of the binary descriptor set
  EXPECT_EQ(advertise["channels"][1]["schema"], R"({"type":"object"})");  // text schemas as they are

  EXPECT_EQ(server->connection_count(), 1u);
  EXPECT_EQ(connection()->target(), "/scene-42?x=1");
}

TEST_F(FoxgloveServerTest, SubscribedMessagesHaveTheBinaryLayoutAndUnsubscribeStopsThem) {
  auto server = Start();
  Client client(server->port());
  client.ReadJson();  // serverInfo
  client.ReadJson();  // advertise
  client.Send(R"({"op":"subscribe","subscriptions":[{"id":7,"channelId":1}]})");
  uint64_t last = 0;
  for (int i = 0; i < 5; ++i) {
    const Message m = client.Read();
    ASSERT_FALSE(m.text);
    ASSERT_GE(m.data.size(), 13u);
    EXPECT_EQ(m.data[0], 0x01);                 // opcode: message data
    EXPECT_EQ(LittleEndian(m.data, 1, 4), 7u);  // the client's subscription id
    const uint64_t t = LittleEndian(m.data, 5, 8);
    EXPECT_GT(t, last);
    last = t;
    EXPECT_EQ(m.data.substr(13), Payload(t));  // every byte, the zero included
  }

  client.Send(R"({"op":"unsubscribe","subscriptionIds":[7]})");
  ReadUntilStatus(client);  // message data queued before the unsubscribe may still arrive up to here
  EXPECT_FALSE(connection()->HasSubscribers(1));
  std::this_thread::sleep_for(20ms);  // lets the producer's loop run (it would send, were the subscription left)
  EXPECT_TRUE(ReadUntilStatus(client).empty()) << "message data after the unsubscribe";
}

TEST_F(FoxgloveServerTest, RefusesAClientWithoutTheSubprotocol) {
  auto server = Start();
  EXPECT_EQ(UpgradeWithout(server->port()), beast::http::status::bad_request);
  EXPECT_EQ(server->connection_count(), 0u);
  EXPECT_EQ(destroyed_, 0);  // on_open never ran, so no producer was made
  EXPECT_EQ(connection(), nullptr);
}

TEST_F(FoxgloveServerTest, BadInputGetsAStatusAndTheConnectionStaysUsable) {
  auto server = Start();
  Client client(server->port());
  client.ReadJson();
  client.ReadJson();
  const std::pair<std::string, int> cases[] = {
      {"not json {", 2},
      {"[1, 2]", 2},
      {R"({"op":"subscribe","subscriptions":[{"id":-1,"channelId":1}]})", 2},
      {R"({"op":"unsubscribe"})", 2},
      {R"({"op":"subscribe","subscriptions":[{"id":1,"channelId":99}]})", 1},  // not advertised
      {R"({"op":"getParameters"})", 1},                                       // not offered
  };
  for (const auto& [text, level] : cases) {
    client.Send(text);
    const json status = client.ReadJson();
    EXPECT_EQ(status["op"], "status") << text;
    EXPECT_EQ(status["level"], level) << text << ": " << status.dump();
  }
  client.Send(R"({"op":"subscribe","subscriptions":[{"id":3,"channelId":1}]})");
  const Message m = client.Read();
  EXPECT_FALSE(m.text);
  EXPECT_EQ(LittleEndian(m.data, 1, 4), 3u);
}

TEST_F(FoxgloveServerTest, TheProducerIsDestroyedWhenTheClientLeaves) {
  auto server = Start();
  {
    Client client(server->port());
    client.ReadJson();
    client.Close();
    ASSERT_TRUE(WaitFor([&] { return server->connection_count() == 0; }));
    EXPECT_EQ(destroyed_, 1);
  }
  {
    Client client(server->port());
    client.ReadJson();
    client.Send(R"({"op":"subscribe","subscriptions":[{"id":1,"channelId":1}]})");
    client.Read();
    client.Drop();  // mid-stream, no close handshake
    ASSERT_TRUE(WaitFor([&] { return server->connection_count() == 0; }));
    EXPECT_EQ(destroyed_, 2);
  }
  // A connection kept past its close takes nothing more and does not block.
  connection()->SendMessage(1, 1, "late");
  connection()->SendStatus(0, "late");
  EXPECT_FALSE(connection()->HasSubscribers(1));
}

TEST_F(FoxgloveServerTest, AClientThatNeverReadsCausesDropsNotBlocking) {
  auto server = Start(/*max_queued_bytes=*/256 << 10);
  Client client(server->port());
  client.Send(R"({"op":"subscribe","subscriptions":[{"id":1,"channelId":2}]})");
  ASSERT_TRUE(WaitFor([&] { return connection() && connection()->HasSubscribers(2); }));
  const std::string payload(64 << 10, 'x');
  // 128 MiB: more than the socket buffers on both ends (tens of MiB at most) and the 256 KiB queue can hold.
  for (int i = 0; i < 2048; ++i) connection()->SendMessage(2, i, payload);  // each call returns
  EXPECT_GT(connection()->dropped_messages(), 0u);
  connection()->SendStatus(1, "control messages are queued regardless");
  server.reset();  // with the write stuck: closes the connection and destroys the producer before returning
  EXPECT_EQ(destroyed_, 1);
}

TEST_F(FoxgloveServerTest, DestructorClosesOpenConnections) {
  auto server = Start();
  Client a(server->port());
  Client b(server->port());
  a.ReadJson();
  b.ReadJson();
  ASSERT_TRUE(WaitFor([&] { return server->connection_count() == 2; }));
  server.reset();
  EXPECT_EQ(destroyed_, 2);
}

TEST(FoxgloveServer, BadListenAddressesThrow) {
  using test_util::ExpectError;
  ExpectError([] { FoxgloveServer({"no-port", "n", 1 << 20}, nullptr); }, ErrorCode::kInvalidArgument, {"no-port"});
  ExpectError([] { FoxgloveServer({"127.0.0.1:99999", "n", 1 << 20}, nullptr); }, ErrorCode::kInvalidArgument,
              {"127.0.0.1:99999"});
  FoxgloveServer first({"127.0.0.1:0", "n", 1 << 20}, nullptr);
  const std::string taken = "127.0.0.1:" + std::to_string(first.port());
  ExpectError([&] { FoxgloveServer({taken, "n", 1 << 20}, nullptr); }, ErrorCode::kFailedPrecondition, {taken.c_str()});
}

}  // namespace
}  // namespace graspsim::live
