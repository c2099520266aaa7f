// SCHUNK Motion Protocol (SMP) over CAN for the PG70 gripper, encoded and decoded without I/O.
//
// Facts taken from the issue and SCHUNK's SMP description: the master sends on CAN id 0x500 + module id, the
// module answers on 0x700 + module id and reports errors on 0x300 + module id; data byte 0 is D-Len, the number of
// message bytes that follow (command code, then parameters); floats are IEEE-754 float32, little-endian; command
// codes MOVE_POS 0xB0, MOVE_VEL 0xB5, MOVE_GRIP 0xB7, CMD_STOP 0x91, CMD_REFERENCE 0x92, GET_STATE 0x95.
//
// Assumed here, not confirmed from a primary source (SCHUNK's manual was not at hand; the search tool found no
// public copy) and therefore kept in this one file:
//   - Fragmentation of a message longer than 7 bytes: FRAG_START 0x84 carries the first 6 message bytes (command
//     code first), FRAG_MIDDLE 0x85 the next 6, FRAG_END 0x86 the rest; in every fragment D-Len counts the message
//     bytes from that fragment on, so the first one holds the total length and the last one its own payload.
//   - Error messages: CMD_ERROR 0x88 followed by one error code byte (on 0x300 + id, or 0x700 + id).
//   - Acknowledgements: MOVE_POS answers with the estimated move time (float32, s); MOVE_VEL, MOVE_GRIP, STOP and
//     REFERENCE answer with "OK" (0x4F 0x4B).
//   - GET_STATE request: float32 period (0 = answer once) and a mode byte (0x07 = position, velocity, current);
//     answer: position (mm), velocity (mm/s), current (A) as float32, then the state byte and the error code.
//   - State bits: 0x01 referenced, 0x02 moving, 0x08 warning, 0x10 error, 0x20 brake, 0x40 move end,
//     0x80 position reached.
//   - MOVE_GRIP: a positive current closes the fingers, a negative one opens them.
#pragma once

#include <linux/can.h>

#include <cstdint>
#include <optional>
#include <span>
#include <vector>

namespace graspsim::drivers::pg70::smp {

inline constexpr canid_t kToModule = 0x500;
inline constexpr canid_t kFromModule = 0x700;
inline constexpr canid_t kErrorFromModule = 0x300;

enum Code : uint8_t {
  kMovePos = 0xB0,
  kMoveVel = 0xB5,
  kMoveGrip = 0xB7,
  kStop = 0x91,
  kReference = 0x92,
  kGetState = 0x95,
  kFragStart = 0x84,
  kFragMiddle = 0x85,
  kFragEnd = 0x86,
  kError = 0x88,
};

// Error codes the driver names (assumed values, see above); others are reported by number.
inline constexpr uint8_t kErrorUnknownCommand = 0x04;
inline constexpr uint8_t kErrorWrongDataLength = 0x05;
inline constexpr uint8_t kErrorSoftLow = 0xD5;
inline constexpr uint8_t kErrorSoftHigh = 0xD6;
inline constexpr uint8_t kErrorEmergencyStop = 0xD9;
inline constexpr uint8_t kErrorNotReferenced = 0xDB;  // assumed
inline constexpr uint8_t kErrorOverCurrent = 0xDE;
const char* ErrorName(uint8_t code);

namespace state {
inline constexpr uint8_t kReferenced = 0x01, kMoving = 0x02, kWarning = 0x08, kError = 0x10, kBrake = 0x20,
                         kMoveEnd = 0x40, kPositionReached = 0x80;
}

using Message = std::vector<uint8_t>;  // command code, then parameters

// One message as CAN frames (one frame up to 7 message bytes, fragments beyond).
std::vector<can_frame> EncodeFrames(canid_t id, std::span<const uint8_t> message);

// Collects the frames of one sender into messages. Throws DeviceError(kMalformedFrame) on a frame that breaks the
// framing (dlc < 2, D-Len 0 or beyond the frame, a fragment out of order, D-Len not what is left) and forgets the
// partial message, so the next well-formed message parses.
class Assembler {
 public:
  std::optional<Message> Feed(const can_frame& frame);
  bool idle() const { return expected_ == 0; }

 private:
  Message partial_;
  size_t expected_ = 0;  // message bytes still to come; 0 = between messages
};

void PutFloat(Message& message, float value);
float GetFloat(std::span<const uint8_t> bytes);  // 4 bytes, little-endian

// Requests.
struct Profile {
  float velocity_mm_s, acceleration_mm_s2, current_a;
};
Message MovePos(float position_mm, std::optional<Profile> profile = std::nullopt);
Message MoveVel(float velocity_mm_s, float current_a);
Message MoveGrip(float current_a);
Message Stop();
Message Reference();
Message GetState(float period_s = 0.0f, uint8_t mode = 0x07);
Message Ok(uint8_t code);              // an acknowledgement "code O K"
Message ErrorMessage(uint8_t error);   // CMD_ERROR, code

struct State {
  float position_mm = 0, velocity_mm_s = 0, current_a = 0;
  uint8_t flags = 0;       // state bits
  uint8_t error_code = 0;  // 0: none
  bool operator==(const State&) const = default;
};
Message StateAnswer(const State& state);
// nullopt when the message is not a complete GET_STATE answer.
std::optional<State> ParseState(std::span<const uint8_t> message);

}  // namespace graspsim::drivers::pg70::smp
