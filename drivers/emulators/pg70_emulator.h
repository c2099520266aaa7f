// A Schunk PG70 answering SMP frames (smp_codec.h) on one end of a CAN link (any fd carrying struct can_frame:
// a socketpair end in tests, a raw CAN socket where the kernel has vcan), in a thread of its own. Simple motion:
// MOVE_POS drives toward the target at the requested velocity, MOVE_VEL at a constant velocity until a stroke
// end, MOVE_GRIP closes (or opens) at a speed proportional to the current; closing stops on an emulated object
// and holds it with the commanded current; a reached MOVE_POS target is announced spontaneously (0x94). Requests
// the module cannot run are refused with a D-Len 2 answer: unknown command, wrong length, moves before
// CMD_REFERENCE ("not referenced").
//
// Fault injection for the tests, applied to the next `count` requests:
//   kSilent        the request takes effect, no answer is sent
//   kMalformed     the request takes effect, the answer's framing is broken (a fragment out of order)
//   kErrorMessage  a serious error instead of the answer: the motor stops, CMD_ERROR with the code on 0x300 + id
#pragma once

#include <atomic>
#include <mutex>
#include <optional>
#include <thread>

#include "drivers/pg70/smp_codec.h"

namespace graspsim::drivers::emulators {

namespace smp = pg70::smp;

class Pg70Emulator {
 public:
  struct Options {
    uint8_t module_id = 12;
    double start_position_mm = 70.0;
    double stroke_mm = 70.0;
    std::optional<double> object_width_mm;  // an object this wide between the fingers, or none
    bool chatter = false;                   // send another module's frame before every answer
  };
  enum class Fault { kNone, kSilent, kMalformed, kErrorMessage };

  Pg70Emulator(int fd, Options options);  // owns fd
  ~Pg70Emulator();

  void InjectFault(Fault fault, int count = 1, uint8_t error_code = smp::kErrorOverCurrent);
  smp::State state() const;
  bool moving() const;
  int requests_served() const { return requests_.load(); }
  int malformed_requests() const { return malformed_.load(); }

 private:
  enum class Mode { kIdle, kPosition, kVelocity, kGrip };
  void Run();
  void Handle(const smp::Message& request);
  void Step(double dt_s);
  smp::State StateLocked() const;
  void Send(const smp::Message& message, canid_t base);

  int fd_;
  Options options_;
  mutable std::mutex mutex_;
  Mode mode_ = Mode::kIdle;
  bool referenced_ = false;
  bool blocked_ = false;  // stopped on the object
  bool reached_ = false;
  bool announce_reached_ = false;
  double position_mm_, velocity_mm_s_ = 0.0, target_mm_ = 0.0, speed_mm_s_ = 0.0, current_a_ = 0.0;
  Fault fault_ = Fault::kNone;
  int fault_count_ = 0;
  uint8_t fault_code_ = 0;
  std::atomic<bool> stop_{false};
  std::atomic<int> requests_{0}, malformed_{0};
  std::thread thread_;
};

}  // namespace graspsim::drivers::emulators
