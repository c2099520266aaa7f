// A Foxglove WebSocket server (subprotocol foxglove.websocket.v1,
// https://github.com/foxglove/ws-protocol/blob/main/docs/spec.md): transport only. It speaks the protocol's
// handshake, channel advertisement, subscriptions and binary message data; what is advertised and sent is up to
// the producer that OpenHandler attaches to each connection. Boost.Asio runs on one thread owned by the server,
// so the process's gRPC threads are never borrowed and a caller of this API never blocks on a client.
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

namespace graspsim::live {

namespace detail {
struct ServerState;  // shared with the connections, which may outlive the server (foxglove_session.h)
}  // namespace detail

struct ChannelInfo {
  uint32_t id = 0;              // unique per connection
  std::string topic;            // "/tf"
  std::string encoding;         // message encoding: "protobuf" | "cdr" | "json"
  std::string schema_name;      // "foxglove.FrameTransforms"
  std::string schema_encoding;  // "protobuf" | "ros2msg" | "jsonschema"
  // Raw schema bytes. For protobuf a serialized FileDescriptorSet (binary): the server base64-encodes it in the
  // advertise JSON, as the protocol asks. ros2msg and jsonschema are text and are sent as they are.
  std::string schema;
};

// One connected client. Thread-safe; no method blocks: each posts its work to the server's io thread.
class Connection {
 public:
  virtual ~Connection() = default;
  virtual void Advertise(const std::vector<ChannelInfo>& channels) = 0;    // op "advertise"
  virtual void Unadvertise(const std::vector<uint32_t>& channel_ids) = 0;  // op "unadvertise"
  // Sends to the client's subscription of this channel (binary opcode 0x01). Dropped (and counted) when the
  // connection's outgoing queue would exceed max_queued_bytes: a slow client never slows the caller.
  virtual void SendMessage(uint32_t channel_id, uint64_t log_time_ns, std::string_view payload) = 0;
  virtual bool HasSubscribers(uint32_t channel_id) const = 0;  // cheap: lets the producer skip encoding
  virtual void SendStatus(int level, const std::string& message) = 0;  // op "status": 0 info, 1 warning, 2 error
  virtual void Close(const std::string& reason) = 0;
  virtual uint64_t dropped_messages() const = 0;
  virtual const std::string& target() const = 0;  // the HTTP request target of the upgrade, e.g. "/scene-id?x=1"
};

struct FoxgloveServerOptions {
  std::string listen = "127.0.0.1:8765";  // host:port; port 0 picks a free one
  std::string name = "graspsim";          // serverInfo's name
  size_t max_queued_bytes = 8 << 20;      // per connection; message data beyond it is dropped
};

// Called on the io thread once the handshake is done. Returns an object kept alive for as long as the connection
// is open (the producer feeding it) and destroyed, on the io thread, right after it closes; may return nullptr.
using OpenHandler = std::function<std::shared_ptr<void>(std::shared_ptr<Connection> connection)>;

class FoxgloveServer {
 public:
  // Binds and starts serving. Throws graspsim::Error naming the address: kInvalidArgument when `listen` is not
  // host:port, kFailedPrecondition when it cannot be bound.
  FoxgloveServer(FoxgloveServerOptions options, OpenHandler on_open);
  // Closes every connection and joins the io thread; the handler's objects are destroyed before it returns.
  // Not to be called on the io thread (from an OpenHandler or a producer's destructor): it would join itself.
  ~FoxgloveServer();
  FoxgloveServer(const FoxgloveServer&) = delete;
  FoxgloveServer& operator=(const FoxgloveServer&) = delete;

  int port() const;
  size_t connection_count() const;  // connections past the handshake and not yet closed

 private:
  std::shared_ptr<detail::ServerState> state_;
};

}  // namespace graspsim::live
