#include "live/foxglove_server.h"

#include <charconv>
#include <chrono>
#include <exception>
#include <vector>

#include "core/error.h"
#include "core/log.h"
#include "live/foxglove_session.h"

namespace graspsim::live {
namespace {

using detail::asio::ip::tcp;
using detail::ServerState;
using detail::Session;

// "host:port", "[v6]:port"; a host name is resolved (localhost).
tcp::endpoint ResolveListen(detail::asio::io_context& ioc, const std::string& listen) {
  const size_t colon = listen.rfind(':');
  int port = -1;
  if (colon != std::string::npos) {
    const char* end = listen.data() + listen.size();
    if (std::from_chars(listen.data() + colon + 1, end, port).ptr != end) port = -1;
  }
  if (colon == std::string::npos || colon == 0 || port < 0 || port > 65535) {
    throw Error(ErrorCode::kInvalidArgument, "listen: '" + listen + "' is not host:port");
  }
  std::string host = listen.substr(0, colon);
  if (host.size() > 2 && host.front() == '[' && host.back() == ']') host = host.substr(1, host.size() - 2);
  boost::system::error_code ec;
  const auto results = tcp::resolver(ioc).resolve(host, std::to_string(port), tcp::resolver::numeric_service, ec);
  if (ec || results.empty()) {
    throw Error(ErrorCode::kInvalidArgument, "listen: cannot resolve '" + listen + "': " + ec.message());
  }
  return results.begin()->endpoint();
}

void Accept(const std::shared_ptr<ServerState>& state) {
  state->acceptor.async_accept([state](boost::system::error_code ec, tcp::socket socket) {
    if (state->stopping) return;  // accepted as the server shut down: dropping the socket closes it
    if (ec) {
      // Out of descriptors or the like: keep serving the clients already here and retry in a while, not in a
      // busy loop.
      Log(LogLevel::kWarn, "foxglove accept failed", {{"error", ec.message()}});
      state->retry_timer.expires_after(std::chrono::milliseconds(100));
      state->retry_timer.async_wait([state](boost::system::error_code ec) {
        if (!ec && !state->stopping) Accept(state);
      });
      return;
    }
    const uint64_t id = state->next_session++;
    auto session = std::make_shared<Session>(state, std::move(socket), id);
    state->sessions[id] = session;
    session->Start();
    Accept(state);
  });
}

}  // namespace

FoxgloveServer::FoxgloveServer(FoxgloveServerOptions options, OpenHandler on_open)
    : state_(std::make_shared<ServerState>()) {
  state_->options = std::move(options);
  state_->on_open = std::move(on_open);
  state_->session_id = std::to_string(std::chrono::system_clock::now().time_since_epoch().count());
  const std::string& listen = state_->options.listen;
  const tcp::endpoint endpoint = ResolveListen(state_->ioc, listen);
  boost::system::error_code ec;
  tcp::acceptor& acceptor = state_->acceptor;
  acceptor.open(endpoint.protocol(), ec);
  if (!ec) acceptor.set_option(tcp::acceptor::reuse_address(true), ec);
  if (!ec) acceptor.bind(endpoint, ec);
  if (!ec) acceptor.listen(detail::asio::socket_base::max_listen_connections, ec);
  if (ec) throw Error(ErrorCode::kFailedPrecondition, "listen: cannot listen on '" + listen + "': " + ec.message());
  state_->port = acceptor.local_endpoint().port();
  Accept(state_);
  state_->io_thread = std::thread([state = state_.get()] {
    // A handler that throws (a producer's destructor, say) must not stop the clients' io: log and run on.
    for (;;) {
      try {
        state->ioc.run();
        return;
      } catch (const std::exception& e) {
        Log(LogLevel::kError, "foxglove io thread: handler threw", {{"error", e.what()}});
      }
    }
  });
  Log(LogLevel::kInfo, "foxglove listening", {{"address", listen}, {"port", std::to_string(state_->port)}});
}

FoxgloveServer::~FoxgloveServer() {
  // Without the acceptor and the sockets nothing is left to wait on, so run() returns once every session has
  // finished, which destroys the handler's objects on the io thread before the join.
  detail::asio::post(state_->ioc, [state = state_.get()] {
    state->stopping = true;
    boost::system::error_code ignored;
    state->acceptor.close(ignored);
    state->retry_timer.cancel();
    std::vector<std::shared_ptr<Session>> open;
    for (const auto& [id, weak] : state->sessions) {
      if (auto session = weak.lock()) open.push_back(std::move(session));
    }
    for (const auto& session : open) session->Abort();
  });
  state_->io_thread.join();
}

int FoxgloveServer::port() const { return state_->port; }

size_t FoxgloveServer::connection_count() const { return state_->connection_count.load(); }

}  // namespace graspsim::live
