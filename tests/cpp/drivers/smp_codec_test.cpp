// SMP framing for the PG70, without I/O: known byte sequences, fragmentation of long messages and its
// reassembly, and every way a frame can break the framing (each a clear error that does not poison the next
// message).
#include "drivers/pg70/smp_codec.h"

#include <vector>

#include <gtest/gtest.h>

#include "drivers/common/device_error.h"

namespace graspsim::drivers::pg70::smp {
namespace {

using Bytes = std::vector<uint8_t>;

Bytes Data(const can_frame& f) { return Bytes(f.data, f.data + f.can_dlc); }

can_frame RawFrame(canid_t id, Bytes data) {
  can_frame f{};
  f.can_id = id;
  f.can_dlc = static_cast<uint8_t>(data.size());
  for (size_t i = 0; i < data.size(); ++i) f.data[i] = data[i];
  return f;
}

std::optional<Message> FeedAll(Assembler& assembler, const std::vector<can_frame>& frames) {
  std::optional<Message> out;
  for (const can_frame& f : frames) {
    EXPECT_FALSE(out) << "message completed before its last frame";
    out = assembler.Feed(f);
  }
  return out;
}

void ExpectMalformed(Assembler& assembler, const can_frame& frame, const char* part) {
  try {
    assembler.Feed(frame);
    ADD_FAILURE() << "no error for a frame that should break the framing (" << part << ")";
  } catch (const DeviceError& error) {
    EXPECT_EQ(error.failure(), DeviceFailure::kMalformedFrame);
    EXPECT_NE(std::string(error.what()).find(part), std::string::npos) << error.what();
  }
}

TEST(Pg70Smp, ShortCommandsFitOneFrame) {
  const auto stop = EncodeFrames(kToModule + 12, Stop());
  ASSERT_EQ(stop.size(), 1u);
  EXPECT_EQ(stop[0].can_id, 0x50Cu);
  EXPECT_EQ(Data(stop[0]), (Bytes{0x01, 0x91}));
  EXPECT_EQ(Data(EncodeFrames(kToModule + 12, Reference())[0]), (Bytes{0x01, 0x92}));
  // 10.0f is 0x41200000: little-endian 00 00 20 41.
  EXPECT_EQ(Data(EncodeFrames(kToModule + 12, MovePos(10.0f))[0]), (Bytes{0x05, 0xB0, 0x00, 0x00, 0x20, 0x41}));
  // -1.5 A of MOVE_GRIP: 0xBFC00000.
  EXPECT_EQ(Data(EncodeFrames(kToModule + 1, MoveGrip(-1.5f))[0]), (Bytes{0x05, 0xB7, 0x00, 0x00, 0xC0, 0xBF}));
  EXPECT_EQ(Data(EncodeFrames(kToModule + 1, GetState())[0]), (Bytes{0x06, 0x95, 0, 0, 0, 0, 0x07}));
}

TEST(Pg70Smp, SchunkDocumentationExamples) {
  // SMP v1.41 examples. GET STATE every 1 s, position only: "0x501 06 95 00 00 80 3F 01".
  const auto request = EncodeFrames(kToModule + 1, GetState(1.0f, 0x01));
  ASSERT_EQ(request.size(), 1u);
  EXPECT_EQ(request[0].can_id, 0x501u);
  EXPECT_EQ(Data(request[0]), (Bytes{0x06, 0x95, 0x00, 0x00, 0x80, 0x3F, 0x01}));
  // Its answer "0x701 07 95 36 89 81 3F 02 00": position 1.011 mm, moving, no error.
  Assembler assembler;
  const auto answer = assembler.Feed(RawFrame(0x701, {0x07, 0x95, 0x36, 0x89, 0x81, 0x3F, 0x02, 0x00}));
  ASSERT_TRUE(answer);
  const auto state = ParseState(*answer, 0x01);
  ASSERT_TRUE(state);
  EXPECT_NEAR(state->position_mm, 1.011f, 1e-3);
  EXPECT_EQ(state->flags, state::kMoving);
  EXPECT_EQ(state->error_code, 0);
  EXPECT_FALSE(ParseState(*answer, 0x07));  // the wrong mode does not parse
  // MOVE POS answer "05 B0 CD CC 04 41": the move takes 8.3 s.
  EXPECT_FLOAT_EQ(GetFloat(Bytes{0xCD, 0xCC, 0x04, 0x41}), 8.3f);
  // CMD ERROR on 0x300 + id: "0x301 02 88 74" (motor voltage low).
  EXPECT_EQ(Data(EncodeFrames(kErrorFromModule + 1, ErrorMessage(kErrorMotorVoltageLow))[0]),
            (Bytes{0x02, 0x88, 0x74}));
  // CMD ACK and its answer: "0x501 01 8B", "0x701 03 8B 4F 4B".
  EXPECT_EQ(Data(EncodeFrames(kFromModule + 1, Ok(kAck))[0]), (Bytes{0x03, 0x8B, 0x4F, 0x4B}));
}

TEST(Pg70Smp, LongMovePosIsFragmentedWithDLenCountingDown) {
  // 17 bytes: B0, position 10, velocity 1 (0x3F800000), acceleration 2 (0x40000000), current 0.5 (0x3F000000).
  const auto frames = EncodeFrames(kToModule + 12, MovePos(10.0f, Profile{1.0f, 2.0f, 0.5f}));
  ASSERT_EQ(frames.size(), 3u);
  EXPECT_EQ(Data(frames[0]), (Bytes{0x11, 0x84, 0xB0, 0x00, 0x00, 0x20, 0x41, 0x00}));
  EXPECT_EQ(Data(frames[1]), (Bytes{0x0B, 0x85, 0x00, 0x80, 0x3F, 0x00, 0x00, 0x00}));
  EXPECT_EQ(Data(frames[2]), (Bytes{0x05, 0x86, 0x40, 0x00, 0x00, 0x00, 0x3F}));
  Assembler assembler;
  EXPECT_EQ(FeedAll(assembler, frames), MovePos(10.0f, Profile{1.0f, 2.0f, 0.5f}));
  EXPECT_TRUE(assembler.idle());
}

TEST(Pg70Smp, MoveVelWithCurrentIsTwoFragments) {
  // 9 bytes: B5, velocity 11.1 mm/s (0x4131999A, the documentation's MOVE VEL example), current 1 A.
  const auto frames = EncodeFrames(kToModule + 12, MoveVel(11.1f, 1.0f));
  ASSERT_EQ(frames.size(), 2u);
  EXPECT_EQ(Data(frames[0]), (Bytes{0x09, 0x84, 0xB5, 0x9A, 0x99, 0x31, 0x41, 0x00}));
  EXPECT_EQ(Data(frames[1]), (Bytes{0x03, 0x86, 0x00, 0x80, 0x3F}));
}

TEST(Pg70Smp, FragmentBoundaries) {
  const Message seven{0xB5, 1, 2, 3, 4, 5, 6};
  EXPECT_EQ(EncodeFrames(kToModule, seven).size(), 1u);
  EXPECT_EQ(EncodeFrames(kToModule, seven)[0].can_dlc, 8);
  const Message eight{0xB5, 1, 2, 3, 4, 5, 6, 7};
  const auto two = EncodeFrames(kToModule, eight);
  ASSERT_EQ(two.size(), 2u);
  EXPECT_EQ(Data(two[1]), (Bytes{0x02, 0x86, 6, 7}));
  const Message twelve{0xB5, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11};  // exactly two full fragments
  const auto full = EncodeFrames(kToModule, twelve);
  ASSERT_EQ(full.size(), 2u);
  EXPECT_EQ(full[1].data[1], kFragEnd);
  for (const Message& m : {seven, eight, twelve}) {
    Assembler assembler;
    EXPECT_EQ(FeedAll(assembler, EncodeFrames(kToModule, m)), m);
  }
}

TEST(Pg70Smp, StateAnswerRoundTripsThroughThreeFragments) {
  const State state{.position_mm = 34.25f, .velocity_mm_s = -12.5f, .current_a = 1.75f,
                    .flags = state::kReferenced | state::kMoving, .error_code = 0};
  const auto frames = EncodeFrames(kFromModule + 12, StateAnswer(state));
  ASSERT_EQ(frames.size(), 3u);  // 15 bytes: 6 + 6 + 3
  EXPECT_EQ(frames[0].data[0], 15);
  EXPECT_EQ(frames[2].data[0], 3);
  Assembler assembler;
  const auto message = FeedAll(assembler, frames);
  ASSERT_TRUE(message);
  EXPECT_EQ(ParseState(*message), state);
  EXPECT_FALSE(ParseState(Ok(kGetState)));
}

TEST(Pg70Smp, FloatsAreLittleEndianIeee) {
  for (float v : {0.0f, 1.0f, -2.5f, 68.125f, 1e-6f, 3.4e38f}) {
    Message m;
    PutFloat(m, v);
    EXPECT_EQ(GetFloat(m), v);
  }
  Message m;
  PutFloat(m, 1.0f);
  EXPECT_EQ(m, (Message{0x00, 0x00, 0x80, 0x3F}));
}

TEST(Pg70Smp, BrokenFramingIsAClearErrorAndTheNextMessageStillParses) {
  Assembler assembler;
  ExpectMalformed(assembler, RawFrame(0x70C, {0x01}), "too short");
  ExpectMalformed(assembler, RawFrame(0x70C, {0x00, 0x91}), "D-Len is 0");
  ExpectMalformed(assembler, RawFrame(0x70C, {0x05, 0x91, 'O', 'K'}), "D-Len 5 exceeds the 3 bytes");
  ExpectMalformed(assembler, RawFrame(0x70C, {0x03, 0x86, 1, 2, 3}), "FRAG_END without FRAG_START");
  ExpectMalformed(assembler, RawFrame(0x70C, {0x09, 0x85, 1, 2, 3, 4, 5, 6}), "FRAG_MIDDLE without FRAG_START");
  ExpectMalformed(assembler, RawFrame(0x70C, {0x05, 0x84, 1, 2, 3, 4, 5, 6}), "fits one frame");

  const auto state = EncodeFrames(kFromModule + 12, StateAnswer({}));
  EXPECT_FALSE(assembler.Feed(state[0]));
  ExpectMalformed(assembler, state[2], "D-Len 3 but 9 bytes are still to come");  // a lost middle fragment
  EXPECT_TRUE(assembler.idle());
  EXPECT_FALSE(assembler.Feed(state[0]));
  ExpectMalformed(assembler, RawFrame(0x70C, {0x03, 0x91, 'O', 'K'}), "whole message arrived inside");
  EXPECT_FALSE(assembler.Feed(state[0]));
  ExpectMalformed(assembler, state[0], "FRAG_START inside");

  const auto again = FeedAll(assembler, state);
  ASSERT_TRUE(again);
  EXPECT_TRUE(ParseState(*again));
}

}  // namespace
}  // namespace graspsim::drivers::pg70::smp
