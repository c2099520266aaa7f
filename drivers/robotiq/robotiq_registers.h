// Robotiq 2F-85 register map, encoded and decoded without I/O.
//
// Source: Robotiq 2F-85 & 2F-140 Instruction Manual (public), section 4 "Control": robot output registers
// (commands) start at Modbus address 0x03E8, robot input registers (status) at 0x07D0; each 16-bit register holds
// two bytes, the lower-numbered byte in the high half. Byte layout:
//   command  byte 0 ACTION REQUEST: rACT bit 0, rGTO bit 3, rATR bit 4 (rADR bit 5, unused here)
//            bytes 1-2 reserved, byte 3 rPR (position request), byte 4 rSP (speed), byte 5 rFR (force)
//   status   byte 0 GRIPPER STATUS: gACT bit 0, gGTO bit 3, gSTA bits 4-5, gOBJ bits 6-7
//            byte 1 reserved, byte 2 FAULT STATUS (gFLT low nibble, kFLT high nibble), byte 3 gPR (echo of rPR),
//            byte 4 gPO (position), byte 5 gCU (current, 10 mA per count)
// The manual's own RTU example "09 10 03 E8 00 03 06 09 00 00 FF FF FF 42 29" (close at full speed and force) is
// checked byte for byte in tests/cpp/drivers/robotiq_registers_test.cpp.
#pragma once

#include <array>
#include <cstdint>

namespace graspsim::drivers::robotiq {

inline constexpr uint16_t kCommandAddress = 0x03E8;
inline constexpr uint16_t kStatusAddress = 0x07D0;
inline constexpr int kRegisterCount = 3;  // 6 bytes each way
inline constexpr uint8_t kDefaultUnit = 9;

using Registers = std::array<uint16_t, kRegisterCount>;

struct Command {
  bool rACT = false;  // activate (0 resets the gripper)
  bool rGTO = false;  // go to the requested position (0 stops)
  bool rATR = false;  // automatic release (emergency open)
  uint8_t rPR = 0;    // position request, 0 open .. 255 closed
  uint8_t rSP = 0;    // speed, 0 slowest .. 255 fastest
  uint8_t rFR = 0;    // force, 0 lowest .. 255 highest
  bool operator==(const Command&) const = default;
};

// gSTA: activation state.
enum class ActivationState : uint8_t { kReset = 0, kActivating = 1, kUnused = 2, kActivated = 3 };
// gOBJ: what the fingers are doing; only meaningful while gGTO is 1.
enum class ObjectState : uint8_t {
  kMoving = 0,          // moving toward the requested position
  kContactOpening = 1,  // stopped by an object while opening
  kContactClosing = 2,  // stopped by an object while closing
  kAtRequest = 3,       // at the requested position, no object (or object lost)
};

// gFLT values the driver names; others are reported by number.
inline constexpr uint8_t kFaultNone = 0x00;
inline constexpr uint8_t kFaultActionDelayed = 0x05;    // activation must complete first
inline constexpr uint8_t kFaultActivationBit = 0x07;    // rACT must be set first
inline constexpr uint8_t kFaultOverTemperature = 0x08;  // and higher: major faults
inline constexpr uint8_t kFaultUnderVoltage = 0x0A;
inline constexpr uint8_t kFaultAutoReleaseRunning = 0x0B;
inline constexpr uint8_t kFaultInternal = 0x0C;
inline constexpr uint8_t kFaultActivation = 0x0D;
inline constexpr uint8_t kFaultOverCurrent = 0x0E;
inline constexpr uint8_t kFaultAutoReleaseDone = 0x0F;

struct Status {
  bool gACT = false;
  bool gGTO = false;
  ActivationState gSTA = ActivationState::kReset;
  ObjectState gOBJ = ObjectState::kMoving;
  uint8_t gFLT = 0;  // low nibble of the fault byte
  uint8_t kFLT = 0;  // high nibble: controller-specific fault
  uint8_t gPR = 0;
  uint8_t gPO = 0;
  uint8_t gCU = 0;
  bool operator==(const Status&) const = default;
};

Registers EncodeCommand(const Command& command);
Command DecodeCommand(const Registers& registers);
Registers EncodeStatus(const Status& status);
Status DecodeStatus(const Registers& registers);

const char* FaultName(uint8_t gFLT);  // "none", "over-current", ... or "unknown"

// Unit conversions of the 2F-85 (manual, section 7 specifications): stroke 85 mm; speed 20-150 mm/s; grip force
// 20-235 N. Counts map linearly onto these ranges; 0 counts is fully open (85 mm), 255 fully closed (0 mm).
struct Calibration {
  double stroke_mm = 85.0;
  double min_speed_mm_s = 20.0, max_speed_mm_s = 150.0;
  double min_force_n = 20.0, max_force_n = 235.0;
};
uint8_t PositionCounts(const Calibration& cal, double opening_mm);  // nearest count
double OpeningMm(const Calibration& cal, uint8_t counts);
uint8_t SpeedCounts(const Calibration& cal, double speed_mm_s);
double SpeedMmPerS(const Calibration& cal, uint8_t counts);
uint8_t ForceCounts(const Calibration& cal, double force_n);
inline double CurrentMa(uint8_t gCU) { return 10.0 * gCU; }

}  // namespace graspsim::drivers::robotiq
