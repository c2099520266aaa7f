// Internals of FoxgloveServer: the state the server shares with its connections, and one connection (Session).
// Threading: everything named "io thread" runs on the server's single io thread; the Connection methods run on
// any thread and only take `mu_` and post. Connections may outlive the server (a producer may keep its
// shared_ptr<Connection>), so each holds the shared state, whose io_context must outlive every socket.
#pragma once

#include <atomic>
#include <cstdint>
#include <deque>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <unordered_map>
#include <unordered_set>

#include <boost/asio/ip/tcp.hpp>
#include <boost/asio/steady_timer.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/http.hpp>
#include <boost/beast/websocket.hpp>

#include "live/foxglove_protocol.h"
#include "live/foxglove_server.h"

namespace graspsim::live::detail {

namespace asio = boost::asio;
namespace beast = boost::beast;
namespace http = beast::http;
namespace websocket = beast::websocket;
using tcp = asio::ip::tcp;

class Session;

struct ServerState {
  FoxgloveServerOptions options;
  OpenHandler on_open;
  std::string session_id;  // one per server instance: lets a reconnecting client tell a restarted server apart
  asio::io_context ioc;    // declared before every socket: destroyed after them
  tcp::acceptor acceptor{ioc};
  asio::steady_timer retry_timer{ioc};  // paces accepting again after an accept error
  std::thread io_thread;
  int port = 0;
  std::atomic<size_t> connection_count{0};
  // io thread only: every session from accept to its end, so that shutdown can tear them down.
  std::unordered_map<uint64_t, std::weak_ptr<Session>> sessions;
  uint64_t next_session = 0;
  bool stopping = false;
};

class Session final : public Connection, public std::enable_shared_from_this<Session> {
 public:
  Session(std::shared_ptr<ServerState> server, tcp::socket socket, uint64_t id);
  void Start();  // io thread: reads the upgrade request
  void Abort();  // io thread: closes the socket; pending operations end with errors and Finish runs

  void Advertise(const std::vector<ChannelInfo>& channels) override;
  void Unadvertise(const std::vector<uint32_t>& channel_ids) override;
  void SendMessage(uint32_t channel_id, uint64_t log_time_ns, std::string_view payload) override;
  bool HasSubscribers(uint32_t channel_id) const override;
  void SendStatus(int level, const std::string& message) override;
  void Close(const std::string& reason) override;
  uint64_t dropped_messages() const override { return dropped_.load(); }
  const std::string& target() const override { return target_; }

 private:
  struct Frame {
    std::string bytes;
    bool text = true;
  };

  // Any thread. Counts the frame as queued and posts it to the io thread, unless the session has ended: posting
  // under mu_ means nothing is posted after Finish, when the io thread may be gone for good.
  void Post(Frame frame);

  // io thread.
  void OnRequest(beast::error_code ec);
  void Refuse(const std::string& why);
  void OnAccept(beast::error_code ec);
  void ReadNext();
  void OnRead(beast::error_code ec);
  void HandleText(std::string_view text);
  void Subscribe(const std::vector<protocol::Subscription>& subscriptions);
  void Unsubscribe(const std::vector<uint32_t>& subscription_ids);
  void Enqueue(Frame frame);
  void WriteNext();
  void OnWrite(beast::error_code ec);
  void DropQueued();  // every queued frame but the one being written
  void StartClose(std::string reason);
  void Finish(beast::error_code ec);
  void Release(size_t bytes);

  const std::shared_ptr<ServerState> server_;  // first member: keeps the io_context alive for ws_
  const uint64_t id_;
  websocket::stream<beast::tcp_stream> ws_;
  std::string remote_;
  std::string target_;  // set before on_open, constant after

  // io thread only.
  beast::flat_buffer buffer_;
  http::request<http::string_body> request_;
  asio::steady_timer close_timer_;
  std::deque<Frame> queue_;  // the front is being written when writing_
  bool writing_ = false;
  bool opened_ = false;
  bool closing_ = false;
  bool finished_ = false;
  std::shared_ptr<void> producer_;  // what on_open returned

  // Any thread, under mu_.
  mutable std::mutex mu_;
  bool ended_ = false;
  std::unordered_set<uint32_t> channels_;                           // advertised
  std::unordered_map<uint32_t, uint32_t> subscription_of_channel_;  // one per channel, as the spec allows
  std::unordered_map<uint32_t, uint32_t> channel_of_subscription_;
  size_t queued_bytes_ = 0;  // posted and not yet written
  std::atomic<uint64_t> dropped_{0};
};

}  // namespace graspsim::live::detail
