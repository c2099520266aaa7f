// The behaviour of a Robotiq 2F-85 behind its registers, without I/O: what the emulators answer. Simple physics:
// activation takes a fixed time; with rGTO set the fingers move toward rPR at the speed rSP asks for (20-150 mm/s)
// and stop on an emulated object (gOBJ = contact while closing) or at the request (gOBJ = at request). The current
// is proportional to rFR while holding an object. Faults 0x05 and 0x07 are raised as the manual describes for
// a go-to before activation has completed or with rACT clear; major faults can be raised and are cleared by a
// reset.
#pragma once

#include <optional>

#include "drivers/robotiq/robotiq_registers.h"

namespace graspsim::drivers::emulators {

class RobotiqModel {
 public:
  struct Options {
    robotiq::Calibration calibration;
    std::optional<double> object_opening_mm;  // an object this wide between the fingers, or none
    double activation_time_s = 0.05;
    double start_opening_mm = 85.0;
  };

  explicit RobotiqModel(Options options);

  void WriteCommand(const robotiq::Registers& registers);
  robotiq::Registers StatusRegisters() const { return robotiq::EncodeStatus(status()); }
  robotiq::Command command() const { return command_; }
  robotiq::Status status() const;
  void Step(double dt_s);

  bool moving() const;
  double opening_mm() const;
  void set_object(std::optional<double> opening_mm) { options_.object_opening_mm = opening_mm; }
  // Latches a fault as the gripper would on e.g. over-current; a major one (>= 0x08) stops the fingers until a
  // reset (rACT 0) clears it, as the manual prescribes.
  void raise_fault(uint8_t gFLT) { latched_fault_ = gFLT; }

 private:
  bool activated() const { return command_.rACT && activation_elapsed_s_ >= options_.activation_time_s; }

  Options options_;
  robotiq::Command command_;
  double position_counts_;  // continuous finger position, 0 open .. 255 closed
  double activation_elapsed_s_ = 0.0;
  bool contact_ = false;
  uint8_t latched_fault_ = robotiq::kFaultNone;
};

}  // namespace graspsim::drivers::emulators
