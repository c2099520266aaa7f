// JSON through nlohmann/json (Debian nlohmann-json3-dev, header-only): Debian 12's Boost 1.74 ships Boost.JSON
// only as a compiled library (libboost-json1.74-dev), and these messages are small control traffic.
#include "live/foxglove_protocol.h"

#include <algorithm>
#include <limits>

#include <nlohmann/json.hpp>

namespace graspsim::live::protocol {
namespace {

using nlohmann::json;

// Producer strings (topics, ros2msg schemas) are not guaranteed UTF-8: replace bad bytes instead of throwing.
std::string Dump(const json& j) { return j.dump(-1, ' ', false, json::error_handler_t::replace); }

uint32_t ToId(const json& value, const std::string& what) {
  if (!value.is_number_unsigned() || value.get<uint64_t>() > std::numeric_limits<uint32_t>::max()) {
    throw std::invalid_argument(what + " must be an unsigned 32-bit integer");
  }
  return value.get<uint32_t>();
}

uint32_t GetId(const json& object, const char* key, const std::string& op) {
  const auto it = object.find(key);
  if (it == object.end()) throw std::invalid_argument(op + ": '" + key + "' is missing");
  return ToId(*it, op + ": '" + key + "'");
}

const json& GetArray(const json& message, const char* key, const std::string& op) {
  const auto it = message.find(key);
  if (it == message.end() || !it->is_array()) throw std::invalid_argument(op + ": '" + key + "' must be an array");
  return *it;
}

}  // namespace

std::string ServerInfoJson(const std::string& name, const std::string& session_id) {
  return Dump({{"op", "serverInfo"},
               {"name", name},
               {"capabilities", json::array()},
               {"supportedEncodings", json::array()},
               {"metadata", json::object()},
               {"sessionId", session_id}});
}

std::string StatusJson(int level, const std::string& message) {
  return Dump({{"op", "status"}, {"level", level}, {"message", message}});
}

std::string AdvertiseJson(const std::vector<ChannelInfo>& channels) {
  json list = json::array();
  for (const ChannelInfo& c : channels) {
    // The spec's schema is a string: a binary FileDescriptorSet travels as base64.
    const bool binary = c.schema_encoding == "protobuf";
    list.push_back({{"id", c.id},
                    {"topic", c.topic},
                    {"encoding", c.encoding},
                    {"schemaName", c.schema_name},
                    {"schema", binary ? Base64(c.schema) : c.schema},
                    {"schemaEncoding", c.schema_encoding}});
  }
  return Dump({{"op", "advertise"}, {"channels", std::move(list)}});
}

std::string UnadvertiseJson(const std::vector<uint32_t>& channel_ids) {
  return Dump({{"op", "unadvertise"}, {"channelIds", channel_ids}});
}

std::string MessageDataFrame(uint32_t subscription_id, uint64_t log_time_ns, std::string_view payload) {
  std::string frame(kMessageDataHeaderBytes + payload.size(), '\0');
  frame[0] = 0x01;  // opcode: message data
  for (int i = 0; i < 4; ++i) frame[1 + i] = static_cast<char>(subscription_id >> (8 * i));  // little-endian
  for (int i = 0; i < 8; ++i) frame[5 + i] = static_cast<char>(log_time_ns >> (8 * i));
  payload.copy(frame.data() + kMessageDataHeaderBytes, payload.size());
  return frame;
}

std::string Base64(std::string_view bytes) {
  static constexpr char kAlphabet[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  out.reserve((bytes.size() + 2) / 3 * 4);
  for (size_t i = 0; i < bytes.size(); i += 3) {
    const size_t n = std::min<size_t>(3, bytes.size() - i);
    uint32_t group = 0;
    for (size_t k = 0; k < 3; ++k) group = group << 8 | (k < n ? static_cast<unsigned char>(bytes[i + k]) : 0u);
    for (size_t k = 0; k < 4; ++k) out += k <= n ? kAlphabet[(group >> (18 - 6 * k)) & 63] : '=';
  }
  return out;
}

ClientMessage ParseClientMessage(std::string_view text) {
  const json message = json::parse(text, nullptr, /*allow_exceptions=*/false);
  if (message.is_discarded()) throw std::invalid_argument("message is not valid JSON");
  const auto op = message.find("op");  // end() for anything but an object
  if (op == message.end() || !op->is_string()) throw std::invalid_argument("message has no string 'op'");
  ClientMessage parsed{op->get<std::string>(), {}, {}};
  if (parsed.op == "subscribe") {
    for (const json& s : GetArray(message, "subscriptions", parsed.op)) {
      if (!s.is_object()) throw std::invalid_argument("subscribe: each subscription must be an object");
      parsed.subscriptions.push_back({GetId(s, "id", "subscribe"), GetId(s, "channelId", "subscribe")});
    }
  } else if (parsed.op == "unsubscribe") {
    for (const json& id : GetArray(message, "subscriptionIds", parsed.op)) {
      parsed.subscription_ids.push_back(ToId(id, "unsubscribe: each of 'subscriptionIds'"));
    }
  }
  return parsed;
}

}  // namespace graspsim::live::protocol
