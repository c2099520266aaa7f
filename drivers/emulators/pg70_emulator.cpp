#include "drivers/emulators/pg70_emulator.h"

#include <poll.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>

#include "drivers/common/device_error.h"

namespace graspsim::drivers::emulators {
namespace {

constexpr double kGripSpeedPerAmp = 25.0;  // mm/s per A under MOVE_GRIP, capped at the datasheet's 82 mm/s
constexpr double kMaxSpeed = 82.0;

}  // namespace

Pg70Emulator::Pg70Emulator(int fd, Options options)
    : fd_(fd), options_(options), position_mm_(options.start_position_mm) {
  thread_ = std::thread([this] { Run(); });
}

Pg70Emulator::~Pg70Emulator() {
  stop_ = true;
  thread_.join();
  close(fd_);
}

void Pg70Emulator::InjectFault(Fault fault, int count, uint8_t error_code) {
  std::lock_guard lock(mutex_);
  fault_ = fault;
  fault_count_ = count;
  fault_code_ = error_code;
}

bool Pg70Emulator::moving() const {
  std::lock_guard lock(mutex_);
  return mode_ != Mode::kIdle && !blocked_;
}

smp::State Pg70Emulator::state() const {
  std::lock_guard lock(mutex_);
  return StateLocked();
}

smp::State Pg70Emulator::StateLocked() const {
  const bool moving = mode_ != Mode::kIdle && !blocked_;
  smp::State s;
  s.position_mm = static_cast<float>(position_mm_);
  s.velocity_mm_s = moving ? static_cast<float>(velocity_mm_s_) : 0.0f;
  // Holding an object draws the commanded current; free motion about a third of it.
  s.current_a = static_cast<float>(blocked_ ? std::abs(current_a_) : moving ? 0.3 * std::abs(current_a_) : 0.0);
  s.flags = static_cast<uint8_t>((referenced_ ? smp::state::kReferenced : 0) | (moving ? smp::state::kMoving : 0) |
                                 (!moving ? smp::state::kMoveEnd : 0) | (reached_ ? smp::state::kPositionReached : 0));
  return s;
}

void Pg70Emulator::Step(double dt) {
  if (mode_ == Mode::kIdle || blocked_) return;
  double next = position_mm_ + velocity_mm_s_ * dt;
  if (mode_ == Mode::kPosition && (velocity_mm_s_ >= 0 ? next >= target_mm_ : next <= target_mm_)) {
    next = target_mm_;
    reached_ = true;
    announce_reached_ = true;
  }
  if (options_.object_width_mm && velocity_mm_s_ < 0 && position_mm_ >= *options_.object_width_mm &&
      next <= *options_.object_width_mm) {
    next = *options_.object_width_mm;
    blocked_ = true;
    reached_ = false;
  }
  next = std::clamp(next, 0.0, options_.stroke_mm);
  position_mm_ = next;
  if (!blocked_ && (reached_ || next == 0.0 || next == options_.stroke_mm)) mode_ = Mode::kIdle;
}

void Pg70Emulator::Send(const smp::Message& message, canid_t base) {
  if (options_.chatter) {
    const uint8_t other[] = {smp::kGetState};  // a neighbour module answering its own master
    for (const can_frame& f : smp::EncodeFrames(smp::kFromModule + options_.module_id + 1, other)) {
      (void)!write(fd_, &f, sizeof(f));
    }
  }
  for (const can_frame& frame : smp::EncodeFrames(base + options_.module_id, message)) {
    (void)!write(fd_, &frame, sizeof(frame));
  }
}

void Pg70Emulator::Handle(const smp::Message& request) {
  requests_++;
  Fault fault = Fault::kNone;
  if (fault_count_ > 0) {
    fault = fault_;
    if (--fault_count_ == 0) fault_ = Fault::kNone;
  }
  if (fault == Fault::kErrorMessage) {  // a serious error: the module shuts the motor down and says so on 0x300
    mode_ = Mode::kIdle;
    blocked_ = false;
    Send(smp::ErrorMessage(fault_code_), smp::kErrorFromModule);
    return;
  }
  const uint8_t code = request[0];
  const size_t n = request.size();
  const auto refuse = [&](uint8_t reason) { Send(smp::Refusal(code, reason), smp::kFromModule); };
  const bool is_move = code == smp::kMovePos || code == smp::kMoveVel || code == smp::kMoveGrip;
  const bool length_ok = (code == smp::kMovePos && (n == 5 || n == 17)) || (code == smp::kMoveVel && n == 9) ||
                         (code == smp::kMoveGrip && n == 5) || (code == smp::kStop && n == 1) ||
                         (code == smp::kReference && n == 1) || (code == smp::kGetState && (n == 1 || n == 5 || n == 6));
  const bool known = is_move || code == smp::kStop || code == smp::kReference || code == smp::kGetState;
  if (!known) return refuse(smp::kErrorUnknownCommand);
  if (!length_ok) return refuse(smp::kErrorWrongDataLength);
  if (is_move && !referenced_) return refuse(smp::kErrorNotReferenced);

  smp::Message answer = smp::Ok(code);
  const auto start = [&](Mode mode, double velocity, double current) {
    mode_ = mode;
    velocity_mm_s_ = velocity;
    current_a_ = current;
    blocked_ = reached_ = false;
  };
  const std::span<const uint8_t> params = std::span(request).subspan(1);
  switch (code) {
    case smp::kMovePos: {
      target_mm_ = std::clamp(static_cast<double>(smp::GetFloat(params)), 0.0, options_.stroke_mm);
      const double speed = n == 17 ? smp::GetFloat(params.subspan(4)) : kMaxSpeed;
      const double current = n == 17 ? smp::GetFloat(params.subspan(12)) : 1.0;
      start(Mode::kPosition, target_mm_ >= position_mm_ ? speed : -speed, current);
      answer = {smp::kMovePos};
      smp::PutFloat(answer, static_cast<float>(speed > 0 ? std::abs(target_mm_ - position_mm_) / speed : 0.0));
      break;
    }
    case smp::kMoveVel:
      start(Mode::kVelocity, smp::GetFloat(params), smp::GetFloat(params.subspan(4)));
      break;
    case smp::kMoveGrip: {
      const double current = smp::GetFloat(params);
      start(Mode::kGrip, -std::copysign(std::min(kMaxSpeed, kGripSpeedPerAmp * std::abs(current)), current), current);
      break;
    }
    case smp::kStop:
      mode_ = Mode::kIdle;
      blocked_ = false;
      break;
    case smp::kReference:
      referenced_ = true;
      break;
    case smp::kGetState:
      answer = smp::StateAnswer(StateLocked());
      break;
  }
  if (fault == Fault::kSilent) return;
  if (fault == Fault::kMalformed) {
    can_frame broken{};  // a FRAG_END that no FRAG_START announced
    broken.can_id = smp::kFromModule + options_.module_id;
    broken.can_dlc = 8;
    broken.data[0] = 6;
    broken.data[1] = smp::kFragEnd;
    (void)!write(fd_, &broken, sizeof(broken));
    return;
  }
  Send(answer, smp::kFromModule);
}

void Pg70Emulator::Run() {
  smp::Assembler assembler;
  auto last = std::chrono::steady_clock::now();
  while (!stop_) {
    pollfd pfd{fd_, POLLIN, 0};
    const int ready = poll(&pfd, 1, 2);
    const auto now = std::chrono::steady_clock::now();
    std::unique_lock lock(mutex_);
    Step(std::chrono::duration<double>(now - last).count());
    last = now;
    if (announce_reached_) {  // the spontaneous "position reached" a real module sends after MOVE_POS
      announce_reached_ = false;
      smp::Message reached{smp::kPosReached};
      smp::PutFloat(reached, static_cast<float>(position_mm_));
      Send(reached, smp::kFromModule);
    }
    if (ready <= 0 || !(pfd.revents & POLLIN)) {
      if (ready > 0) {  // the driver's end was closed: nothing more will come
        lock.unlock();
        std::this_thread::sleep_for(std::chrono::milliseconds(2));
      }
      continue;
    }
    can_frame frame{};
    if (read(fd_, &frame, sizeof(frame)) != sizeof(frame)) continue;
    if ((frame.can_id & CAN_SFF_MASK) != smp::kToModule + options_.module_id) continue;
    try {
      const auto request = assembler.Feed(frame);
      if (request) Handle(*request);
    } catch (const DeviceError&) {  // broken framing from the master: count it, answer nothing
      malformed_++;
    }
  }
}

}  // namespace graspsim::drivers::emulators
