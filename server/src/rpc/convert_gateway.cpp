#include "rpc/convert_gateway.h"

#include <cmath>

#include "core/error.h"
#include "core/format.h"

namespace graspsim::rpc {
namespace {

double Finite(const std::string& field, double value) {
  if (!std::isfinite(value)) ThrowInvalidArgument(field + ": " + FormatNumber(value) + " is not a finite number");
  return value;
}

}  // namespace

gateway::DeviceInfo DeviceFromProto(const v1::Device& device) {
  gateway::DeviceInfo info{.id = device.id(), .kind = device.kind(), .gateway = device.gateway(), .link = device.link()};
  const v1::DeviceLimits& l = device.limits();
  info.limits = {.min_opening = Finite("register_device.limits.min_opening", l.min_opening()),
                 .max_opening = Finite("register_device.limits.max_opening", l.max_opening()),
                 .min_speed = Finite("register_device.limits.min_speed", l.min_speed()),
                 .max_speed = Finite("register_device.limits.max_speed", l.max_speed()),
                 .min_force = Finite("register_device.limits.min_force", l.min_force()),
                 .max_force = Finite("register_device.limits.max_force", l.max_force()),
                 .max_current = Finite("register_device.limits.max_current", l.max_current())};
  return info;
}

gateway::DeviceReading ReadingFromProto(const v1::DeviceReading& r) {
  return {.device_id = r.device_id(),
          .time = r.time(),
          .opening = r.opening(),
          .current = r.current(),
          .moving = r.moving(),
          .object_detected = r.object_detected(),
          .estopped = r.estopped(),
          .fault = r.fault()};
}

gateway::CommandResult ResultFromProto(const v1::CommandResult& r) {
  gateway::CommandResult result;
  result.command_id = r.command_id();
  // A gateway that says "not ok" without a code still failed: keep it a failure.
  result.code = r.ok() ? gateway::Code::kOk
                       : (r.code() == 0 ? gateway::Code::kInternal : static_cast<gateway::Code>(r.code()));
  result.message = r.message();
  if (r.has_reading()) result.reading = ReadingFromProto(r.reading());
  result.gateway_seconds = r.gateway_seconds();
  return result;
}

gateway::Move MoveFromProto(const std::string& field, const v1::Move& move) {
  return {.opening = Finite(field + ".opening", move.opening()),
          .speed = Finite(field + ".speed", move.speed()),
          .force = Finite(field + ".force", move.force())};
}

gateway::Command CommandFromProto(const v1::DeviceCommand& c) {
  using Kind = gateway::Command::Kind;
  if (c.device_id().empty()) ThrowInvalidArgument("device_id: empty");
  gateway::Command command;
  command.device_id = c.device_id();
  command.timeout = Finite("timeout", c.timeout());
  switch (c.command_case()) {
    case v1::DeviceCommand::kMoveTo: command.kind = Kind::kMoveTo; command.value = Finite("move_to", c.move_to()); break;
    case v1::DeviceCommand::kVelocity: command.kind = Kind::kVelocity; command.value = Finite("velocity", c.velocity()); break;
    case v1::DeviceCommand::kMaxForce: command.kind = Kind::kMaxForce; command.value = Finite("max_force", c.max_force()); break;
    case v1::DeviceCommand::kStop: command.kind = Kind::kStop; break;
    case v1::DeviceCommand::kInitialize: command.kind = Kind::kInitialize; break;
    case v1::DeviceCommand::kEstop: command.kind = Kind::kEstop; break;
    case v1::DeviceCommand::kMove: command.kind = Kind::kMove; command.move = MoveFromProto("move", c.move()); break;
    case v1::DeviceCommand::kRead: command.kind = Kind::kRead; break;
    case v1::DeviceCommand::COMMAND_NOT_SET:
      ThrowInvalidArgument("command: none set (one of move_to, velocity, max_force, stop, initialize, estop, move, read)");
  }
  return command;
}

void ToProto(const gateway::DeviceReading& r, v1::DeviceReading* out) {
  out->set_device_id(r.device_id);
  out->set_time(r.time);
  out->set_opening(r.opening);
  out->set_current(r.current);
  out->set_moving(r.moving);
  out->set_object_detected(r.object_detected);
  out->set_fault(r.fault);
  out->set_estopped(r.estopped);
}

void ToProto(const gateway::DeviceInfo& d, v1::Device* out) {
  out->set_id(d.id);
  out->set_kind(d.kind);
  out->set_gateway(d.gateway);
  out->set_link(d.link);
  v1::DeviceLimits* l = out->mutable_limits();
  l->set_min_opening(d.limits.min_opening);
  l->set_max_opening(d.limits.max_opening);
  l->set_min_speed(d.limits.min_speed);
  l->set_max_speed(d.limits.max_speed);
  l->set_min_force(d.limits.min_force);
  l->set_max_force(d.limits.max_force);
  l->set_max_current(d.limits.max_current);
  if (d.last_reading) ToProto(*d.last_reading, out->mutable_last_reading());
}

void ToProto(const gateway::CommandResult& r, v1::CommandResult* out) {
  out->set_command_id(r.command_id);
  out->set_ok(r.ok());
  out->set_code(static_cast<int>(r.code));
  out->set_message(r.message);
  if (r.reading) ToProto(*r.reading, out->mutable_reading());
  out->set_gateway_seconds(r.gateway_seconds);
}

void ToProto(const gateway::Command& c, v1::DeviceCommand* out) {
  using Kind = gateway::Command::Kind;
  out->set_device_id(c.device_id);
  out->set_command_id(c.id);
  out->set_timeout(c.timeout);
  switch (c.kind) {
    case Kind::kMoveTo: out->set_move_to(c.value); break;
    case Kind::kVelocity: out->set_velocity(c.value); break;
    case Kind::kMaxForce: out->set_max_force(c.value); break;
    case Kind::kStop: out->set_stop(true); break;
    case Kind::kInitialize: out->set_initialize(true); break;
    case Kind::kEstop: out->set_estop(true); break;
    case Kind::kRead: out->set_read(true); break;
    case Kind::kMove:
      out->mutable_move()->set_opening(c.move.opening);
      out->mutable_move()->set_speed(c.move.speed);
      out->mutable_move()->set_force(c.move.force);
      break;
  }
}

}  // namespace graspsim::rpc
