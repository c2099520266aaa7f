// The gateway's SMP decoding for the Schunk PG70 (drivers/pg70/smp_codec.h): CAN frames fed to one Assembler, as
// the driver does with what its CAN link receives. Input: frames of 10 bytes (a GET_STATE mode byte, the dlc,
// 8 data bytes); the dlc is taken modulo 9, as the link (drivers/can/can_transport.cpp) drops frames with a
// dlc above 8 before they reach the assembler. A malformed frame throws DeviceError (an Error); the assembler
// must then parse the next well-formed message. Every whole message is offered to ParseState, and must survive
// EncodeFrames → a fresh Assembler unchanged.
#include <cstring>

#include "drivers/common/device_error.h"
#include "drivers/pg70/smp_codec.h"
#include "fuzz_common.h"

namespace smp = graspsim::drivers::pg70::smp;

namespace {

void CheckRoundTrip(const smp::Message& message) {
  smp::Assembler fresh;
  std::optional<smp::Message> out;
  for (const can_frame& frame : smp::EncodeFrames(smp::kFromModule + 12, message)) {
    if (out) graspsim::fuzz::Broken("EncodeFrames: frames after the end of the message");
    out = fresh.Feed(frame);
  }
  if (!out || *out != message) graspsim::fuzz::Broken("EncodeFrames → Assembler changed the message");
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  smp::Assembler assembler;
  for (size_t at = 0; at + 10 <= size; at += 10) {
    can_frame frame{};
    frame.can_id = smp::kFromModule + 12;
    frame.can_dlc = data[at + 1] % 9;
    std::memcpy(frame.data, data + at + 2, 8);
    const uint8_t mode = data[at];
    graspsim::fuzz::Rejects([&] {
      const std::optional<smp::Message> message = assembler.Feed(frame);
      if (!message) return;
      if (message->empty()) graspsim::fuzz::Broken("Assembler: an empty message");
      (void)smp::ParseState(*message, mode);
      (void)smp::ErrorName((*message)[message->size() - 1]);
      // EncodeFrames covers messages up to what fragments can carry; a D-Len byte bounds them at 255.
      if (message->size() <= 255) CheckRoundTrip(*message);
    });
  }
  return 0;
}
