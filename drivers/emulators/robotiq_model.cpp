#include "drivers/emulators/robotiq_model.h"

#include <algorithm>
#include <cmath>

namespace graspsim::drivers::emulators {

using namespace robotiq;

RobotiqModel::RobotiqModel(Options options) : options_(options) {
  position_counts_ = PositionCounts(options_.calibration, options_.start_opening_mm);
}

void RobotiqModel::WriteCommand(const Registers& registers) {
  const Command next = DecodeCommand(registers);
  if (!next.rACT) {  // reset: clears a latched fault; activation starts over when rACT is set again
    activation_elapsed_s_ = 0.0;
    latched_fault_ = kFaultNone;
  }
  // A new request (or a fresh go-to) releases the latched contact; the fingers re-evaluate from where they are.
  if (next.rPR != command_.rPR || (next.rGTO && !command_.rGTO)) contact_ = false;
  command_ = next;
}

bool RobotiqModel::moving() const {
  return activated() && command_.rGTO && !contact_ && latched_fault_ < kFaultOverTemperature &&
         std::abs(command_.rPR - position_counts_) >= 0.5;
}

double RobotiqModel::opening_mm() const { return options_.calibration.stroke_mm * (1.0 - position_counts_ / 255.0); }

void RobotiqModel::Step(double dt_s) {
  if (command_.rACT) activation_elapsed_s_ += dt_s;
  if (!moving()) return;
  const Calibration& cal = options_.calibration;
  const double counts_per_mm = 255.0 / cal.stroke_mm;
  const double step = SpeedMmPerS(cal, command_.rSP) * counts_per_mm * dt_s;
  const double target = command_.rPR;
  double next = position_counts_ + std::clamp(target - position_counts_, -step, step);
  if (options_.object_opening_mm && target > position_counts_) {
    const double object_counts = (cal.stroke_mm - *options_.object_opening_mm) * counts_per_mm;
    if (position_counts_ <= object_counts && next >= object_counts && target > object_counts) {
      next = object_counts;
      contact_ = true;
    }
  }
  position_counts_ = next;
}

Status RobotiqModel::status() const {
  Status s;
  s.gACT = command_.rACT;
  s.gGTO = command_.rGTO;
  s.gSTA = !command_.rACT ? ActivationState::kReset
           : activated()  ? ActivationState::kActivated
                          : ActivationState::kActivating;
  if (latched_fault_ != kFaultNone) s.gFLT = latched_fault_;
  else if (command_.rGTO && !command_.rACT) s.gFLT = kFaultActivationBit;
  else if (command_.rGTO && !activated()) s.gFLT = kFaultActionDelayed;
  if (contact_) s.gOBJ = ObjectState::kContactClosing;
  else if (activated() && command_.rGTO && !moving() && latched_fault_ < kFaultOverTemperature) {
    s.gOBJ = ObjectState::kAtRequest;
  }
  else s.gOBJ = ObjectState::kMoving;
  s.gPR = command_.rPR;
  s.gPO = static_cast<uint8_t>(std::lround(std::clamp(position_counts_, 0.0, 255.0)));
  // About 0.1 A while the motor drives the fingers, up to 0.6 A holding an object at full force.
  s.gCU = contact_ ? static_cast<uint8_t>(10 + command_.rFR * 50 / 255) : moving() ? 10 : 0;
  return s;
}

}  // namespace graspsim::drivers::emulators
