// Robotiq 2F-85 register codec and Modbus framing, without I/O: round trips, and the byte sequences printed in
// the Robotiq 2F-85 instruction manual's Modbus RTU examples (activation, status read, close at full speed).
#include "drivers/robotiq/robotiq_registers.h"

#include <vector>

#include <gtest/gtest.h>

#include "drivers/modbus/modbus_frame.h"

namespace graspsim::drivers::robotiq {
namespace {

using Bytes = std::vector<uint8_t>;

Registers FromPdu(const Bytes& pdu) {  // function, byte count, 3 big-endian registers
  Registers r{};
  for (int i = 0; i < kRegisterCount; ++i) r[i] = static_cast<uint16_t>(pdu[2 + 2 * i] << 8 | pdu[3 + 2 * i]);
  return r;
}

TEST(RobotiqRegisters, CommandRoundTripsEveryField) {
  for (const Command c : {Command{}, Command{.rACT = true}, Command{.rACT = true, .rGTO = true, .rPR = 0xFF, .rSP = 1,
                                                                    .rFR = 0x80},
                          Command{.rACT = true, .rGTO = false, .rATR = true, .rPR = 7, .rSP = 0xFF, .rFR = 0}}) {
    EXPECT_EQ(DecodeCommand(EncodeCommand(c)), c);
  }
}

TEST(RobotiqRegisters, StatusRoundTripsEveryField) {
  Status s{.gACT = true, .gGTO = true, .gSTA = ActivationState::kActivated, .gOBJ = ObjectState::kContactClosing,
           .gFLT = kFaultOverCurrent, .kFLT = 0x9, .gPR = 200, .gPO = 190, .gCU = 33};
  EXPECT_EQ(DecodeStatus(EncodeStatus(s)), s);
  s = Status{.gSTA = ActivationState::kActivating, .gOBJ = ObjectState::kContactOpening};
  EXPECT_EQ(DecodeStatus(EncodeStatus(s)), s);
}

TEST(RobotiqRegisters, ManualActivationRequestBytes) {
  // Manual: "09 10 03 E8 00 03 06 00 00 00 00 00 00 73 30" clears rACT (reset before activation).
  const Bytes frame = modbus::RtuFrame(kDefaultUnit, modbus::WriteRegistersRequest(kCommandAddress, EncodeCommand({})));
  EXPECT_EQ(frame, (Bytes{0x09, 0x10, 0x03, 0xE8, 0x00, 0x03, 0x06, 0, 0, 0, 0, 0, 0, 0x73, 0x30}));
  // Its answer: "09 10 03 E8 00 03 01 30".
  EXPECT_EQ(modbus::RtuFrame(kDefaultUnit, modbus::WriteRegistersResponse(kCommandAddress, 3)),
            (Bytes{0x09, 0x10, 0x03, 0xE8, 0x00, 0x03, 0x01, 0x30}));
}

TEST(RobotiqRegisters, ManualCloseAtFullSpeedAndForceBytes) {
  // Manual: "09 10 03 E8 00 03 06 09 00 00 FF FF FF 42 29": rACT + rGTO, rPR = rSP = rFR = 255.
  const Command close{.rACT = true, .rGTO = true, .rPR = 0xFF, .rSP = 0xFF, .rFR = 0xFF};
  EXPECT_EQ(modbus::RtuFrame(kDefaultUnit, modbus::WriteRegistersRequest(kCommandAddress, EncodeCommand(close))),
            (Bytes{0x09, 0x10, 0x03, 0xE8, 0x00, 0x03, 0x06, 0x09, 0x00, 0x00, 0xFF, 0xFF, 0xFF, 0x42, 0x29}));
}

TEST(RobotiqRegisters, ManualStatusReadBytesAndAnswers) {
  // Manual: "09 03 07 D0 00 01 85 CF" reads the first status register.
  EXPECT_EQ(modbus::RtuFrame(kDefaultUnit, modbus::ReadRegistersRequest(modbus::kReadHoldingRegisters, kStatusAddress, 1)),
            (Bytes{0x09, 0x03, 0x07, 0xD0, 0x00, 0x01, 0x85, 0xCF}));
  // "09 03 02 11 00 55 D5": gACT set, activation in progress.
  const auto activating = modbus::ParseRtuFrame(kDefaultUnit, Bytes{0x09, 0x03, 0x02, 0x11, 0x00, 0x55, 0xD5});
  ASSERT_TRUE(activating);
  const Status a = DecodeStatus({static_cast<uint16_t>((*activating)[2] << 8 | (*activating)[3]), 0, 0});
  EXPECT_TRUE(a.gACT);
  EXPECT_EQ(a.gSTA, ActivationState::kActivating);
  // "09 03 06 B9 00 00 FF BD 00 1D 7C": closed on an object at gPO 0xBD, request 0xFF, no fault.
  const auto closed =
      modbus::ParseRtuFrame(kDefaultUnit, Bytes{0x09, 0x03, 0x06, 0xB9, 0x00, 0x00, 0xFF, 0xBD, 0x00, 0x1D, 0x7C});
  ASSERT_TRUE(closed);
  const Status s = DecodeStatus(FromPdu(*closed));
  EXPECT_TRUE(s.gACT && s.gGTO);
  EXPECT_EQ(s.gSTA, ActivationState::kActivated);
  EXPECT_EQ(s.gOBJ, ObjectState::kContactClosing);
  EXPECT_EQ(s.gFLT, kFaultNone);
  EXPECT_EQ(s.gPR, 0xFF);
  EXPECT_EQ(s.gPO, 0xBD);
  EXPECT_EQ(s.gCU, 0);
}

TEST(RobotiqRegisters, RtuParserRejectsBadCrcAndOtherUnits) {
  Bytes frame{0x09, 0x03, 0x07, 0xD0, 0x00, 0x01, 0x85, 0xCF};
  EXPECT_TRUE(modbus::ParseRtuFrame(9, frame));
  EXPECT_FALSE(modbus::ParseRtuFrame(8, frame));
  frame[7] ^= 0x01;
  EXPECT_FALSE(modbus::ParseRtuFrame(9, frame));
  EXPECT_FALSE(modbus::ParseRtuFrame(9, Bytes{0x09, 0x03}));
}

TEST(RobotiqRegisters, TcpFrameHasMbapHeader) {
  const Bytes pdu = modbus::ReadRegistersRequest(modbus::kReadHoldingRegisters, kStatusAddress, 3);
  EXPECT_EQ(modbus::TcpFrame(0x1234, 9, pdu),
            (Bytes{0x12, 0x34, 0x00, 0x00, 0x00, 0x06, 0x09, 0x03, 0x07, 0xD0, 0x00, 0x03}));
}

TEST(RobotiqRegisters, UnitConversionsCoverTheStroke) {
  const Calibration cal;
  EXPECT_EQ(PositionCounts(cal, 85.0), 0);
  EXPECT_EQ(PositionCounts(cal, 0.0), 255);
  EXPECT_DOUBLE_EQ(OpeningMm(cal, 0), 85.0);
  EXPECT_DOUBLE_EQ(OpeningMm(cal, 255), 0.0);
  for (double mm : {0.0, 12.3, 40.0, 84.9}) EXPECT_NEAR(OpeningMm(cal, PositionCounts(cal, mm)), mm, 85.0 / 255 / 2);
  EXPECT_EQ(SpeedCounts(cal, 20.0), 0);
  EXPECT_EQ(SpeedCounts(cal, 150.0), 255);
  EXPECT_NEAR(SpeedMmPerS(cal, SpeedCounts(cal, 80.0)), 80.0, 130.0 / 255);
  EXPECT_EQ(ForceCounts(cal, 235.0), 255);
  EXPECT_DOUBLE_EQ(CurrentMa(12), 120.0);
  EXPECT_STREQ(FaultName(kFaultOverCurrent), "over-current");
}

}  // namespace
}  // namespace graspsim::drivers::robotiq
