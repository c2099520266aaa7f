// The foxglove.websocket.v1 messages as bytes: JSON text for control, binary frames for message data. No I/O,
// so the session code reads as transport and this file as the spec.
#pragma once

#include <cstdint>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "live/foxglove_server.h"

namespace graspsim::live::protocol {

inline constexpr char kSubprotocol[] = "foxglove.websocket.v1";
inline constexpr size_t kMessageDataHeaderBytes = 1 + 4 + 8;  // opcode, subscription id, log time

// Server to client.
std::string ServerInfoJson(const std::string& name, const std::string& session_id);
std::string StatusJson(int level, const std::string& message);
std::string AdvertiseJson(const std::vector<ChannelInfo>& channels);
std::string UnadvertiseJson(const std::vector<uint32_t>& channel_ids);
std::string MessageDataFrame(uint32_t subscription_id, uint64_t log_time_ns, std::string_view payload);
std::string Base64(std::string_view bytes);

// Client to server: the ops this server acts on.
struct Subscription {
  uint32_t id = 0;
  uint32_t channel_id = 0;
};
struct ClientMessage {
  std::string op;
  std::vector<Subscription> subscriptions;  // op "subscribe"
  std::vector<uint32_t> subscription_ids;   // op "unsubscribe"
};
// Throws std::invalid_argument, its message fit for a status reply, when `text` is not JSON or a subscribe or
// unsubscribe lacks its fields. Other ops come back with only `op` set.
ClientMessage ParseClientMessage(std::string_view text);

}  // namespace graspsim::live::protocol
