// SCHUNK Motion Protocol (SMP) over CAN for the PG70 gripper, encoded and decoded without I/O.
//
// Confirmed from SCHUNK's SMP documentation (v1.41, HTML edition; the copy found with the search tool is at
// cs.unc.edu/Research/stc/FAQs/Schunk/SMP_v_1_41) and the issue:
//   - the master sends on CAN id 0x500 + module id, the module answers on 0x700 + id, and sends CMD ERROR (0x88)
//     messages on 0x300 + id ("0x301: 02 88 74");
//   - data byte 0 is D-Len, the number of bytes that follow including the command code; then the command code,
//     then its parameters; floats are IEEE-754 float32, little-endian;
//   - every request is answered with the same command code; an answer with D-Len 2 is a refusal whose one
//     parameter is the reason code;
//   - MOVE_POS 0xB0 answers with the estimated move time, float32 s ("05 B0 00 00 20 41" -> "05 B0 CD CC 04 41");
//     MOVE_VEL 0xB5 takes velocity and an optional current and answers "OK" (0x4F 0x4B), as do CMD_STOP 0x91,
//     CMD_REFERENCE 0x92, MOVE_GRIP 0xB7 and CMD ACK 0x8B;
//   - GET_STATE 0x95 takes a period (float32 s, 0 = once) and a mode byte (0x01 position, 0x02 velocity,
//     0x04 current); the answer carries the selected floats, then the state byte and the error byte
//     ("06 95 00 00 80 3F 01" -> "07 95 <position> 02 00": moving, no error);
//   - the module announces a reached position spontaneously with 0x94 and the position; 0x89 warnings and 0x8A
//     infos are spontaneous too.
// Assumed, not found in what the search tool could reach, and kept in this one file:
//   - fragmentation of a message longer than 7 bytes: FRAG_START 0x84 carries the first 6 message bytes (command
//     code first), FRAG_MIDDLE 0x85 the next 6, FRAG_END 0x86 the rest; in every fragment D-Len counts the message
//     bytes from that fragment on, so the first one holds the total length and the last one its own payload;
//   - the order velocity-after-position-then-current of GET_STATE mode 0x07, and the state bits other than
//     0x02 moving (0x01 referenced, 0x08 warning, 0x10 error, 0x20 brake, 0x40 move end, 0x80 position reached);
//   - the reason codes other than those seen in examples (0xD6 soft high, 0xDA tow, 0x74 motor voltage low);
//   - MOVE_GRIP's sign: a positive current closes the fingers, a negative one opens them.
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
  kPosReached = 0x94,  // spontaneous
  kError = 0x88,       // spontaneous, on 0x300 + id
  kWarning = 0x89,     // spontaneous
  kInfo = 0x8A,        // spontaneous
  kAck = 0x8B,
};

// Reason codes the driver names (values seen in SCHUNK's examples, and assumed ones, see above).
inline constexpr uint8_t kErrorUnknownCommand = 0x04;
inline constexpr uint8_t kErrorWrongDataLength = 0x05;
inline constexpr uint8_t kErrorSoftLow = 0xD5;
inline constexpr uint8_t kErrorSoftHigh = 0xD6;
inline constexpr uint8_t kErrorEmergencyStop = 0xD9;
inline constexpr uint8_t kErrorNotReferenced = 0xDB;  // assumed
inline constexpr uint8_t kErrorTow = 0xDA;
inline constexpr uint8_t kErrorOverCurrent = 0xDE;
inline constexpr uint8_t kErrorMotorVoltageLow = 0x74;
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
Message Refusal(uint8_t code, uint8_t reason);  // the D-Len 2 answer of a failed request

struct State {
  float position_mm = 0, velocity_mm_s = 0, current_a = 0;
  uint8_t flags = 0;       // state bits
  uint8_t error_code = 0;  // 0: none
  bool operator==(const State&) const = default;
};
Message StateAnswer(const State& state);
// The GET_STATE answer for a request with `mode`: the selected floats in the order position, velocity, current
// (unselected ones stay 0), then state and error bytes. nullopt when the message is not such an answer.
std::optional<State> ParseState(std::span<const uint8_t> message, uint8_t mode = 0x07);

}  // namespace graspsim::drivers::pg70::smp
