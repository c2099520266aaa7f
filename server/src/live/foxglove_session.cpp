#include "live/foxglove_session.h"

#include <algorithm>
#include <chrono>
#include <exception>

#include "core/log.h"

namespace graspsim::live::detail {
namespace {

constexpr auto kRequestTimeout = std::chrono::seconds(30);  // to send the upgrade request, or read the refusal
constexpr auto kCloseTimeout = std::chrono::seconds(5);     // for a client that never answers the close
constexpr size_t kMaxClientMessageBytes = 1 << 20;          // clients send small JSON: bounds what garbage costs
constexpr size_t kMaxCloseReasonBytes = 123;                // RFC 6455, 5.5: control frame payload <= 125

std::string_view View(beast::string_view s) { return {s.data(), s.size()}; }

// Sec-WebSocket-Protocol may repeat and holds comma-separated tokens.
bool OffersSubprotocol(const http::request<http::string_body>& request) {
  const auto [begin, end] = request.equal_range(http::field::sec_websocket_protocol);
  for (auto field = begin; field != end; ++field) {
    std::string_view list = View(field->value());
    while (!list.empty()) {
      const size_t comma = std::min(list.find(','), list.size());
      std::string_view token = list.substr(0, comma);
      list.remove_prefix(std::min(comma + 1, list.size()));
      while (!token.empty() && (token.front() == ' ' || token.front() == '\t')) token.remove_prefix(1);
      while (!token.empty() && (token.back() == ' ' || token.back() == '\t')) token.remove_suffix(1);
      if (token == protocol::kSubprotocol) return true;
    }
  }
  return false;
}

// Cut at a UTF-8 character boundary: browsers fail a connection whose close reason is not UTF-8.
std::string CloseReason(std::string reason) {
  if (reason.size() <= kMaxCloseReasonBytes) return reason;
  size_t size = kMaxCloseReasonBytes;
  while (size > 0 && (static_cast<unsigned char>(reason[size]) & 0xC0) == 0x80) --size;
  reason.resize(size);
  return reason;
}

}  // namespace

Session::Session(std::shared_ptr<ServerState> server, tcp::socket socket, uint64_t id)
    : server_(std::move(server)), id_(id), ws_(std::move(socket)), close_timer_(server_->ioc) {
  beast::error_code ec;
  const tcp::endpoint remote = ws_.next_layer().socket().remote_endpoint(ec);
  if (!ec) remote_ = remote.address().to_string() + ":" + std::to_string(remote.port());
}

void Session::Start() {
  beast::get_lowest_layer(ws_).expires_after(kRequestTimeout);
  http::async_read(ws_.next_layer(), buffer_, request_,
                   [self = shared_from_this()](beast::error_code ec, size_t) { self->OnRequest(ec); });
}

void Session::OnRequest(beast::error_code ec) {
  if (ec) return Finish(ec);
  target_ = std::string(View(request_.target()));
  if (!websocket::is_upgrade(request_)) return Refuse("expected a WebSocket upgrade");
  if (!OffersSubprotocol(request_)) return Refuse(std::string("offer the subprotocol ") + protocol::kSubprotocol);
  beast::get_lowest_layer(ws_).expires_never();  // the websocket's own timeouts (and keep-alive pings) take over
  ws_.set_option(websocket::stream_base::timeout::suggested(beast::role_type::server));
  ws_.set_option(websocket::stream_base::decorator(
      [](websocket::response_type& response) { response.set(http::field::sec_websocket_protocol, protocol::kSubprotocol); }));
  ws_.read_message_max(kMaxClientMessageBytes);
  ws_.async_accept(request_, [self = shared_from_this()](beast::error_code ec) { self->OnAccept(ec); });
}

void Session::Refuse(const std::string& why) {
  Log(LogLevel::kInfo, "foxglove client refused", {{"remote", remote_}, {"target", target_}, {"why", why}});
  auto response = std::make_shared<http::response<http::string_body>>(http::status::bad_request, request_.version());
  response->set(http::field::content_type, "text/plain");
  response->keep_alive(false);
  response->body() = why + "\n";
  response->prepare_payload();
  http::async_write(ws_.next_layer(), *response,
                    [self = shared_from_this(), response](beast::error_code ec, size_t) { self->Finish(ec); });
}

void Session::OnAccept(beast::error_code ec) {
  if (ec) return Finish(ec);
  request_ = {};
  buffer_.consume(buffer_.size());
  opened_ = true;
  ++server_->connection_count;
  Log(LogLevel::kInfo, "foxglove client connected", {{"remote", remote_}, {"target", target_}});
  Post({protocol::ServerInfoJson(server_->options.name, server_->session_id), true});
  if (server_->on_open) {
    try {
      producer_ = server_->on_open(shared_from_this());
    } catch (const std::exception& e) {
      Log(LogLevel::kError, "foxglove open handler failed", {{"target", target_}, {"error", e.what()}});
      StartClose("internal error");
    }
  }
  ReadNext();
}

void Session::ReadNext() {
  ws_.async_read(buffer_, [self = shared_from_this()](beast::error_code ec, size_t) { self->OnRead(ec); });
}

void Session::OnRead(beast::error_code ec) {
  if (ec) return Finish(ec);
  if (ws_.got_text()) {
    HandleText({static_cast<const char*>(buffer_.data().data()), buffer_.size()});
  } else {
    SendStatus(1, "binary client messages are not supported (no clientPublish capability)");
  }
  buffer_.consume(buffer_.size());
  ReadNext();
}

void Session::HandleText(std::string_view text) {
  protocol::ClientMessage message;
  try {
    message = protocol::ParseClientMessage(text);
  } catch (const std::exception& e) {
    return SendStatus(2, e.what());
  }
  if (message.op == "subscribe") {
    Subscribe(message.subscriptions);
  } else if (message.op == "unsubscribe") {
    Unsubscribe(message.subscription_ids);
  } else {
    SendStatus(1, "unsupported op '" + message.op + "'");
  }
}

void Session::Subscribe(const std::vector<protocol::Subscription>& subscriptions) {
  std::vector<std::string> problems;
  {
    std::lock_guard lock(mu_);
    for (const protocol::Subscription& s : subscriptions) {
      const std::string ids = "subscription " + std::to_string(s.id) + " of channel " + std::to_string(s.channel_id);
      if (!channels_.contains(s.channel_id)) {
        problems.push_back(ids + " ignored: the channel is not advertised");
      } else if (channel_of_subscription_.contains(s.id)) {
        problems.push_back(ids + " ignored: the subscription id is in use");
      } else if (subscription_of_channel_.contains(s.channel_id)) {
        problems.push_back(ids + " ignored: the channel already has a subscription");
      } else {
        subscription_of_channel_[s.channel_id] = s.id;
        channel_of_subscription_[s.id] = s.channel_id;
      }
    }
  }
  for (const std::string& problem : problems) SendStatus(1, problem);
}

void Session::Unsubscribe(const std::vector<uint32_t>& subscription_ids) {
  std::vector<uint32_t> unknown;
  {
    std::lock_guard lock(mu_);
    for (uint32_t id : subscription_ids) {
      const auto it = channel_of_subscription_.find(id);
      if (it == channel_of_subscription_.end()) {
        unknown.push_back(id);
        continue;
      }
      subscription_of_channel_.erase(it->second);
      channel_of_subscription_.erase(it);
    }
  }
  for (uint32_t id : unknown) SendStatus(1, "unsubscribe: no subscription " + std::to_string(id));
}

void Session::Advertise(const std::vector<ChannelInfo>& channels) {
  {
    std::lock_guard lock(mu_);
    for (const ChannelInfo& channel : channels) channels_.insert(channel.id);
  }
  Post({protocol::AdvertiseJson(channels), true});
}

void Session::Unadvertise(const std::vector<uint32_t>& channel_ids) {
  {
    std::lock_guard lock(mu_);
    for (uint32_t id : channel_ids) {
      channels_.erase(id);
      const auto it = subscription_of_channel_.find(id);
      if (it == subscription_of_channel_.end()) continue;
      channel_of_subscription_.erase(it->second);
      subscription_of_channel_.erase(it);
    }
  }
  Post({protocol::UnadvertiseJson(channel_ids), true});
}

void Session::SendMessage(uint32_t channel_id, uint64_t log_time_ns, std::string_view payload) {
  uint32_t subscription = 0;
  {
    std::lock_guard lock(mu_);
    const auto it = subscription_of_channel_.find(channel_id);
    if (it == subscription_of_channel_.end()) return;
    subscription = it->second;
    // Beyond the bound the newest message is dropped; an empty queue takes one message of any size, which
    // would otherwise never be sent.
    const size_t bytes = protocol::kMessageDataHeaderBytes + payload.size();
    if (queued_bytes_ > 0 && queued_bytes_ + bytes > server_->options.max_queued_bytes) {
      ++dropped_;
      return;
    }
  }
  Post({protocol::MessageDataFrame(subscription, log_time_ns, payload), false});
}

bool Session::HasSubscribers(uint32_t channel_id) const {
  std::lock_guard lock(mu_);
  return subscription_of_channel_.contains(channel_id);
}

void Session::SendStatus(int level, const std::string& message) { Post({protocol::StatusJson(level, message), true}); }

void Session::Close(const std::string& reason) {
  std::lock_guard lock(mu_);
  if (!ended_) asio::post(server_->ioc, [self = shared_from_this(), reason] { self->StartClose(reason); });
}

void Session::Post(Frame frame) {
  std::lock_guard lock(mu_);
  if (ended_) return;
  queued_bytes_ += frame.bytes.size();
  asio::post(server_->ioc,
             [self = shared_from_this(), frame = std::move(frame)]() mutable { self->Enqueue(std::move(frame)); });
}

void Session::Enqueue(Frame frame) {
  if (closing_ || finished_) return Release(frame.bytes.size());
  queue_.push_back(std::move(frame));
  if (!writing_) WriteNext();
}

void Session::WriteNext() {
  writing_ = true;
  ws_.text(queue_.front().text);
  ws_.async_write(asio::buffer(queue_.front().bytes),
                  [self = shared_from_this()](beast::error_code ec, size_t) { self->OnWrite(ec); });
}

void Session::OnWrite(beast::error_code ec) {
  writing_ = false;
  Release(queue_.front().bytes.size());
  queue_.pop_front();
  if (ec) return Abort();  // the pending read fails in turn and Finish runs
  if (!queue_.empty()) WriteNext();
}

void Session::DropQueued() {
  const size_t keep = writing_ ? 1 : 0;
  size_t bytes = 0;
  for (size_t i = keep; i < queue_.size(); ++i) bytes += queue_[i].bytes.size();
  queue_.resize(std::min(keep, queue_.size()));
  Release(bytes);
}

void Session::Release(size_t bytes) {
  std::lock_guard lock(mu_);
  queued_bytes_ -= bytes;
}

void Session::StartClose(std::string reason) {
  if (!opened_ || closing_ || finished_) return;
  closing_ = true;
  DropQueued();  // what is still queued would only delay the close
  // The client's answer ends the pending read, and with it the session; the timer ends it without an answer.
  ws_.async_close({websocket::close_code::normal, CloseReason(std::move(reason))},
                  [self = shared_from_this()](beast::error_code) {});
  close_timer_.expires_after(kCloseTimeout);
  close_timer_.async_wait([self = shared_from_this()](beast::error_code ec) {
    if (!ec) self->Abort();
  });
}

void Session::Abort() {
  close_timer_.cancel();
  // Turning the websocket's timeouts off cancels its timer: the io thread must not wait on it at shutdown.
  ws_.set_option(websocket::stream_base::timeout{websocket::stream_base::none(), websocket::stream_base::none(), false});
  beast::get_lowest_layer(ws_).close();
}

void Session::Finish(beast::error_code ec) {
  if (finished_) return;
  finished_ = true;
  {
    std::lock_guard lock(mu_);
    ended_ = true;
    subscription_of_channel_.clear();
    channel_of_subscription_.clear();
  }
  DropQueued();
  Abort();  // the socket may still be open, e.g. after the refusal was sent or a message was too large
  server_->sessions.erase(id_);
  if (!opened_) return;
  producer_.reset();  // on the io thread, right after the close, as OpenHandler promises
  --server_->connection_count;
  Log(LogLevel::kInfo, "foxglove client disconnected",
      {{"remote", remote_}, {"target", target_}, {"why", ec.message()}, {"dropped_messages", std::to_string(dropped_.load())}});
}

}  // namespace graspsim::live::detail
