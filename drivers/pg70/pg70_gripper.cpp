#include "drivers/pg70/pg70_gripper.h"

#include <cmath>
#include <cstdio>

namespace graspsim::drivers::pg70 {
namespace {

std::string Hex(uint8_t code) {
  char text[8];
  std::snprintf(text, sizeof(text), "0x%02X", code);
  return text;
}

}  // namespace

Gripper::Gripper(std::unique_ptr<can::CanTransport> link, Config config) : link_(std::move(link)), config_(config) {
  CheckInRange("pg70.module_id", config_.module_id, 1, 255);  // 0 is not a module address
}

std::string Gripper::Name() const {
  return link_->name() + " pg70 module " + std::to_string(config_.module_id);
}

smp::Message Gripper::ExchangeOnce(const smp::Message& request) {
  const canid_t id = config_.module_id;
  for (const can_frame& frame : smp::EncodeFrames(smp::kToModule + id, request)) link_->Send(frame);
  // One assembler per sender id: a CMD ERROR on 0x300 + id may arrive between the fragments of an answer.
  smp::Assembler answers, errors;
  const auto deadline = std::chrono::steady_clock::now() + config_.timeout;
  for (;;) {
    const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(deadline - std::chrono::steady_clock::now());
    const auto frame = left.count() > 0 ? link_->Receive(left) : std::nullopt;
    if (!frame) {
      throw DeviceError(DeviceFailure::kTimeout, Name() + ": no answer to command " + Hex(request[0]) + " within " +
                                                     std::to_string(config_.timeout.count()) + " ms");
    }
    const canid_t from = frame->can_id & CAN_SFF_MASK;
    if (from != smp::kFromModule + id && from != smp::kErrorFromModule + id) continue;  // another module's traffic
    std::optional<smp::Message> message;
    try {
      message = (from == smp::kFromModule + id ? answers : errors).Feed(*frame);
    } catch (const DeviceError& error) {
      throw DeviceError(error.failure(), Name() + ": " + error.what());
    }
    if (!message) continue;
    if ((*message)[0] == smp::kError) {
      const uint8_t code = message->size() >= 2 ? (*message)[1] : 0;
      throw DeviceError(DeviceFailure::kDeviceException,
                        Name() + ": module reports error " + Hex(code) + " (" + smp::ErrorName(code) + ")");
    }
    if ((*message)[0] == request[0] && message->size() == 2) {  // D-Len 2: the module refused the request
      const uint8_t reason = (*message)[1];
      throw DeviceError(DeviceFailure::kDeviceException, Name() + ": module refused command " + Hex(request[0]) +
                                                             ": " + Hex(reason) + " (" + smp::ErrorName(reason) + ")");
    }
    if ((*message)[0] == request[0]) return *message;
    // Spontaneous messages (position reached, warnings, infos) and late answers to other commands: not ours.
  }
}

smp::Message Gripper::Exchange(const smp::Message& request) {
  try {
    return ExchangeOnce(request);
  } catch (const DeviceError& error) {
    StopAndRethrow(error);
  }
}

void Gripper::StopAndRethrow(const DeviceError& error) {
  std::string outcome = "; stop sent";
  try {
    const smp::Message answer = ExchangeOnce(smp::Stop());
    if (answer != smp::Ok(smp::kStop)) outcome = "; stop not acknowledged";
  } catch (const DeviceError& stop_error) {
    outcome = std::string("; stop failed too: ") + stop_error.what();
  }
  throw DeviceError(error.failure(), error.what() + outcome);
}

void Gripper::ExpectOk(const smp::Message& request) {
  const smp::Message answer = Exchange(request);
  if (answer != smp::Ok(request[0])) {
    StopAndRethrow(DeviceError(DeviceFailure::kMalformedFrame, Name() + ": answer to command " +
                                                                   Hex(request[0]) + " is not OK"));
  }
}

void Gripper::Reference() { ExpectOk(smp::Reference()); }

double Gripper::MovePosition(double position_mm, double velocity_mm_s, double acceleration_mm_s2, double current_a) {
  const Limits& lim = config_.limits;
  CheckInRange("move_position.position_mm", position_mm, lim.min_position_mm, lim.max_position_mm);
  // A zero velocity, acceleration or current would leave the module "moving" forever without getting anywhere.
  CheckAboveAtMost("move_position.velocity_mm_s", velocity_mm_s, 0.0, lim.max_velocity_mm_s);
  CheckAboveAtMost("move_position.acceleration_mm_s2", acceleration_mm_s2, 0.0, lim.max_acceleration_mm_s2);
  CheckAboveAtMost("move_position.current_a", current_a, 0.0, lim.max_current_a);
  const smp::Message answer = Exchange(smp::MovePos(static_cast<float>(position_mm),
                                                    smp::Profile{static_cast<float>(velocity_mm_s),
                                                                 static_cast<float>(acceleration_mm_s2),
                                                                 static_cast<float>(current_a)}));
  if (answer.size() != 5) {
    StopAndRethrow(DeviceError(DeviceFailure::kMalformedFrame,
                               Name() + ": MOVE_POS answer has " + std::to_string(answer.size()) + " bytes, not 5"));
  }
  return smp::GetFloat(std::span(answer).subspan(1));
}

void Gripper::MoveVelocity(double velocity_mm_s, double current_a) {
  const Limits& lim = config_.limits;
  CheckInRange("move_velocity.velocity_mm_s", velocity_mm_s, -lim.max_velocity_mm_s, lim.max_velocity_mm_s);
  CheckAboveAtMost("move_velocity.current_a", current_a, 0.0, lim.max_current_a);
  ExpectOk(smp::MoveVel(static_cast<float>(velocity_mm_s), static_cast<float>(current_a)));
}

void Gripper::Grip(double current_a) {
  CheckInRange("grip.current_a", current_a, -config_.limits.max_current_a, config_.limits.max_current_a);
  if (current_a == 0.0) ThrowInvalidArgument("grip.current_a: 0 has no direction (positive closes, negative opens)");
  ExpectOk(smp::MoveGrip(static_cast<float>(current_a)));
}

void Gripper::Stop() {
  // No fallback for a failed stop: the error goes to the caller (the gateway's watchdog escalates).
  const smp::Message answer = ExchangeOnce(smp::Stop());
  if (answer != smp::Ok(smp::kStop)) throw DeviceError(DeviceFailure::kMalformedFrame, Name() + ": stop not acknowledged");
}

smp::State Gripper::GetState() {
  const smp::Message answer = Exchange(smp::GetState());
  const auto state = smp::ParseState(answer);
  if (!state) {
    StopAndRethrow(DeviceError(DeviceFailure::kMalformedFrame, Name() + ": GET_STATE answer has " +
                                                                   std::to_string(answer.size()) + " bytes, not 15"));
  }
  return *state;
}

}  // namespace graspsim::drivers::pg70
