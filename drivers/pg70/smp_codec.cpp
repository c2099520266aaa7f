#include "drivers/pg70/smp_codec.h"

#include <algorithm>
#include <bit>
#include <cstring>
#include <string>

#include "drivers/common/device_error.h"

namespace graspsim::drivers::pg70::smp {
namespace {

constexpr size_t kSingleMax = 7;     // D-Len + 7 bytes fill one frame
constexpr size_t kFragPayload = 6;   // D-Len + fragment code + 6 bytes

can_frame Frame(canid_t id, uint8_t dlen, std::span<const uint8_t> head, std::span<const uint8_t> body) {
  can_frame frame{};
  frame.can_id = id;
  frame.data[0] = dlen;
  size_t n = 1;
  for (uint8_t b : head) frame.data[n++] = b;
  for (uint8_t b : body) frame.data[n++] = b;
  frame.can_dlc = static_cast<uint8_t>(n);
  return frame;
}

[[noreturn]] void Malformed(const can_frame& frame, const std::string& why) {
  char id[16];
  std::snprintf(id, sizeof(id), "0x%03X", frame.can_id & CAN_SFF_MASK);
  throw DeviceError(DeviceFailure::kMalformedFrame, std::string("smp frame on ") + id + ": " + why);
}

}  // namespace

const char* ErrorName(uint8_t code) {
  switch (code) {
    case kErrorUnknownCommand: return "unknown command";
    case kErrorWrongDataLength: return "wrong data length";
    case kErrorSoftLow: return "soft limit low";
    case kErrorSoftHigh: return "soft limit high";
    case kErrorEmergencyStop: return "emergency stop";
    case kErrorNotReferenced: return "not referenced";
    case kErrorTow: return "tow error";
    case kErrorOverCurrent: return "over current";
    case kErrorMotorVoltageLow: return "motor voltage low";
    default: return "unknown error";
  }
}

std::vector<can_frame> EncodeFrames(canid_t id, std::span<const uint8_t> message) {
  if (message.size() <= kSingleMax) return {Frame(id, static_cast<uint8_t>(message.size()), {}, message)};
  std::vector<can_frame> frames;
  size_t sent = 0;
  while (sent < message.size()) {
    const size_t left = message.size() - sent;
    const size_t take = std::min(left, kFragPayload);
    const uint8_t code = sent == 0 ? kFragStart : left <= kFragPayload ? kFragEnd : kFragMiddle;
    const uint8_t head[] = {code};
    frames.push_back(Frame(id, static_cast<uint8_t>(left), head, message.subspan(sent, take)));
    sent += take;
  }
  return frames;
}

std::optional<Message> Assembler::Feed(const can_frame& frame) {
  const size_t dlc = frame.can_dlc;
  const size_t dlen = dlc >= 1 ? frame.data[0] : 0;
  const uint8_t code = dlc >= 2 ? frame.data[1] : 0;
  const bool fragment = code == kFragStart || code == kFragMiddle || code == kFragEnd;
  const auto fail = [&](const std::string& why) {
    partial_.clear();
    expected_ = 0;
    Malformed(frame, why);
  };
  if (dlc < 2) fail("dlc " + std::to_string(dlc) + " is too short for D-Len and a command");
  if (dlen == 0) fail("D-Len is 0");

  if (!fragment) {
    if (expected_ != 0) fail("a whole message arrived inside a fragmented one");
    if (dlen > dlc - 1) fail("D-Len " + std::to_string(dlen) + " exceeds the " + std::to_string(dlc - 1) + " bytes sent");
    return Message(frame.data + 1, frame.data + 1 + dlen);
  }

  const size_t payload = dlc - 2;
  if (code == kFragStart) {
    if (expected_ != 0) fail("FRAG_START inside a fragmented message");
    if (dlen <= kSingleMax) fail("FRAG_START for a message of " + std::to_string(dlen) + " bytes, which fits one frame");
    if (payload != kFragPayload) fail("FRAG_START carries " + std::to_string(payload) + " bytes, not 6");
  } else {
    if (expected_ == 0) fail(code == kFragEnd ? "FRAG_END without FRAG_START" : "FRAG_MIDDLE without FRAG_START");
    if (dlen != expected_) {
      fail("D-Len " + std::to_string(dlen) + " but " + std::to_string(expected_) + " bytes are still to come");
    }
    const bool last = dlen <= kFragPayload;
    if (last != (code == kFragEnd)) fail(last ? "the last fragment is not FRAG_END" : "FRAG_END before the end");
    if (payload != std::min(dlen, kFragPayload)) {
      fail("fragment carries " + std::to_string(payload) + " bytes, expected " +
           std::to_string(std::min(dlen, kFragPayload)));
    }
  }
  partial_.insert(partial_.end(), frame.data + 2, frame.data + 2 + payload);
  expected_ = dlen - payload;
  if (expected_ != 0) return std::nullopt;
  Message done;
  done.swap(partial_);
  return done;
}

void PutFloat(Message& message, float value) {
  const uint32_t bits = std::bit_cast<uint32_t>(value);
  for (int i = 0; i < 4; ++i) message.push_back(static_cast<uint8_t>(bits >> (8 * i)));
}

float GetFloat(std::span<const uint8_t> bytes) {
  uint32_t bits = 0;
  for (int i = 0; i < 4; ++i) bits |= static_cast<uint32_t>(bytes[i]) << (8 * i);
  return std::bit_cast<float>(bits);
}

Message MovePos(float position_mm, std::optional<Profile> profile) {
  Message m{kMovePos};
  PutFloat(m, position_mm);
  if (profile) {
    PutFloat(m, profile->velocity_mm_s);
    PutFloat(m, profile->acceleration_mm_s2);
    PutFloat(m, profile->current_a);
  }
  return m;
}

Message MoveVel(float velocity_mm_s, float current_a) {
  Message m{kMoveVel};
  PutFloat(m, velocity_mm_s);
  PutFloat(m, current_a);
  return m;
}

Message MoveGrip(float current_a) {
  Message m{kMoveGrip};
  PutFloat(m, current_a);
  return m;
}

Message Stop() { return {kStop}; }
Message Reference() { return {kReference}; }

Message GetState(float period_s, uint8_t mode) {
  Message m{kGetState};
  PutFloat(m, period_s);
  m.push_back(mode);
  return m;
}

Message Ok(uint8_t code) { return {code, 'O', 'K'}; }
Message ErrorMessage(uint8_t error) { return {kError, error}; }
Message Refusal(uint8_t code, uint8_t reason) { return {code, reason}; }

Message StateAnswer(const State& s) {
  Message m{kGetState};
  PutFloat(m, s.position_mm);
  PutFloat(m, s.velocity_mm_s);
  PutFloat(m, s.current_a);
  m.push_back(s.flags);
  m.push_back(s.error_code);
  return m;
}

std::optional<State> ParseState(std::span<const uint8_t> m, uint8_t mode) {
  float* fields[3];
  State state;
  size_t n = 0;
  if (mode & 0x01) fields[n++] = &state.position_mm;
  if (mode & 0x02) fields[n++] = &state.velocity_mm_s;
  if (mode & 0x04) fields[n++] = &state.current_a;
  if (m.size() != 1 + 4 * n + 2 || m[0] != kGetState) return std::nullopt;
  for (size_t i = 0; i < n; ++i) *fields[i] = GetFloat(m.subspan(1 + 4 * i));
  state.flags = m[1 + 4 * n];
  state.error_code = m[2 + 4 * n];
  return state;
}

}  // namespace graspsim::drivers::pg70::smp
