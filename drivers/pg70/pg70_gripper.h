// Schunk PG70 device logic over a CanTransport speaking SMP (smp_codec.h). Units: position in mm (the module's
// axis: 0 closed .. 70 open, two fingers of 35 mm), velocity in mm/s, acceleration in mm/s^2, current in A.
// Each call sends one request and waits for the module's answer to that command; frames of other ids and
// spontaneous messages are skipped; a D-Len 2 answer (a refusal) or a CMD ERROR throws kDeviceException.
// Limits are checked before anything is sent (kInvalidArgument naming the field and value). A timeout, a
// malformed answer or an SMP error message throws DeviceError after a best-effort CMD_STOP, so the module is
// left stopped. Not thread-safe: one caller at a time, since answers are matched to the one open request.
#pragma once

#include <chrono>
#include <cstdint>
#include <memory>

#include "drivers/can/can_transport.h"
#include "drivers/common/device_error.h"
#include "drivers/pg70/smp_codec.h"

namespace graspsim::drivers::pg70 {

// Datasheet PG70: 35 mm per finger, 82 mm/s; a current of 3.5 A is about its 200 N gripping force.
struct Limits {
  double min_position_mm = 0.0, max_position_mm = 70.0;
  double max_velocity_mm_s = 82.0;
  double max_acceleration_mm_s2 = 320.0;
  double max_current_a = 3.5;
};

struct Config {
  uint8_t module_id = 12;
  Limits limits;
  std::chrono::milliseconds timeout{100};  // per answer
};

class Gripper {
 public:
  Gripper(std::unique_ptr<can::CanTransport> link, Config config);

  void Reference();
  // Returns the module's estimate of the move time (s).
  double MovePosition(double position_mm, double velocity_mm_s, double acceleration_mm_s2, double current_a);
  void MoveVelocity(double velocity_mm_s, double current_a);  // signed velocity: positive opens
  void Grip(double current_a);                                // signed current: positive closes
  void Stop();
  smp::State GetState();

  const Config& config() const { return config_; }

 private:
  // Sends `request` and returns the answer to its command code.
  smp::Message Exchange(const smp::Message& request);
  smp::Message ExchangeOnce(const smp::Message& request);
  void ExpectOk(const smp::Message& request);
  [[noreturn]] void StopAndRethrow(const DeviceError& error);
  std::string Name() const;

  std::unique_ptr<can::CanTransport> link_;
  Config config_;
};

}  // namespace graspsim::drivers::pg70
