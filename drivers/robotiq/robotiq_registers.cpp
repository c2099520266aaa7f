#include "drivers/robotiq/robotiq_registers.h"

#include <algorithm>
#include <cmath>

namespace graspsim::drivers::robotiq {
namespace {

uint16_t Pack(uint8_t high, uint8_t low) { return static_cast<uint16_t>(high << 8 | low); }
uint8_t High(uint16_t value) { return static_cast<uint8_t>(value >> 8); }
uint8_t Low(uint16_t value) { return static_cast<uint8_t>(value & 0xFF); }

uint8_t ToCounts(double fraction) {
  return static_cast<uint8_t>(std::lround(std::clamp(fraction, 0.0, 1.0) * 255.0));
}

}  // namespace

Registers EncodeCommand(const Command& c) {
  const uint8_t action = static_cast<uint8_t>((c.rACT ? 0x01 : 0) | (c.rGTO ? 0x08 : 0) | (c.rATR ? 0x10 : 0));
  return {Pack(action, 0), Pack(0, c.rPR), Pack(c.rSP, c.rFR)};
}

Command DecodeCommand(const Registers& r) {
  const uint8_t action = High(r[0]);
  return {.rACT = (action & 0x01) != 0,
          .rGTO = (action & 0x08) != 0,
          .rATR = (action & 0x10) != 0,
          .rPR = Low(r[1]),
          .rSP = High(r[2]),
          .rFR = Low(r[2])};
}

Registers EncodeStatus(const Status& s) {
  const uint8_t status = static_cast<uint8_t>((s.gACT ? 0x01 : 0) | (s.gGTO ? 0x08 : 0) |
                                              (static_cast<uint8_t>(s.gSTA) & 0x3) << 4 |
                                              (static_cast<uint8_t>(s.gOBJ) & 0x3) << 6);
  const uint8_t fault = static_cast<uint8_t>((s.kFLT & 0x0F) << 4 | (s.gFLT & 0x0F));
  return {Pack(status, 0), Pack(fault, s.gPR), Pack(s.gPO, s.gCU)};
}

Status DecodeStatus(const Registers& r) {
  const uint8_t status = High(r[0]);
  const uint8_t fault = High(r[1]);
  return {.gACT = (status & 0x01) != 0,
          .gGTO = (status & 0x08) != 0,
          .gSTA = static_cast<ActivationState>((status >> 4) & 0x3),
          .gOBJ = static_cast<ObjectState>((status >> 6) & 0x3),
          .gFLT = static_cast<uint8_t>(fault & 0x0F),
          .kFLT = static_cast<uint8_t>(fault >> 4),
          .gPR = Low(r[1]),
          .gPO = High(r[2]),
          .gCU = Low(r[2])};
}

const char* FaultName(uint8_t gFLT) {
  switch (gFLT) {
    case kFaultNone: return "none";
    case kFaultActionDelayed: return "action delayed, activation must complete first";
    case kFaultActivationBit: return "activation bit must be set first";
    case kFaultOverTemperature: return "over temperature";
    case kFaultUnderVoltage: return "under voltage";
    case kFaultAutoReleaseRunning: return "automatic release in progress";
    case kFaultInternal: return "internal fault";
    case kFaultActivation: return "activation fault";
    case kFaultOverCurrent: return "over-current";
    case kFaultAutoReleaseDone: return "automatic release completed";
    default: return "unknown";
  }
}

uint8_t PositionCounts(const Calibration& cal, double opening_mm) {
  return ToCounts((cal.stroke_mm - opening_mm) / cal.stroke_mm);
}
double OpeningMm(const Calibration& cal, uint8_t counts) { return cal.stroke_mm * (1.0 - counts / 255.0); }
uint8_t SpeedCounts(const Calibration& cal, double speed_mm_s) {
  return ToCounts((speed_mm_s - cal.min_speed_mm_s) / (cal.max_speed_mm_s - cal.min_speed_mm_s));
}
double SpeedMmPerS(const Calibration& cal, uint8_t counts) {
  return cal.min_speed_mm_s + (cal.max_speed_mm_s - cal.min_speed_mm_s) * counts / 255.0;
}
uint8_t ForceCounts(const Calibration& cal, double force_n) {
  return ToCounts((force_n - cal.min_force_n) / (cal.max_force_n - cal.min_force_n));
}

}  // namespace graspsim::drivers::robotiq
