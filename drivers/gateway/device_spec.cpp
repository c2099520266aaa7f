#include "drivers/gateway/device_spec.h"

#include <linux/can.h>

#include "core/error.h"
#include "drivers/can/can_transport.h"
#include "drivers/modbus/modbus_transport.h"
#include "drivers/pg70/pg70_gripper.h"
#include "drivers/robotiq/robotiq_gripper.h"

namespace graspsim::drivers::gateway {
namespace {

int Integer(const std::string& flag, const std::string& what, const std::string& text, int low, int high) {
  size_t used = 0;
  int value = 0;
  try {
    value = std::stoi(text, &used);
  } catch (const std::exception&) {
    used = 0;
  }
  if (used != text.size() || text.empty() || value < low || value > high) {
    ThrowInvalidArgument("--device=" + flag + ": " + what + " '" + text + "' is not an integer in [" +
                         std::to_string(low) + ", " + std::to_string(high) + "]");
  }
  return value;
}

// "A[:B]": A and the optional B.
std::pair<std::string, std::string> SplitLast(const std::string& text) {
  const size_t colon = text.rfind(':');
  if (colon == std::string::npos) return {text, ""};
  return {text.substr(0, colon), text.substr(colon + 1)};
}

}  // namespace

DeviceSpec ParseDeviceSpec(const std::string& text, int index) {
  DeviceSpec spec;
  std::string rest = text;
  const size_t eq = rest.find('=');
  if (eq != std::string::npos) {
    spec.id = rest.substr(0, eq);
    rest = rest.substr(eq + 1);
    if (spec.id.empty()) ThrowInvalidArgument("--device=" + text + ": empty id before '='");
  }
  const size_t colon = rest.find(':');
  spec.transport = rest.substr(0, colon);
  spec.address = colon == std::string::npos ? "" : rest.substr(colon + 1);
  if (spec.transport != "robotiq-tcp" && spec.transport != "robotiq-rtu" && spec.transport != "pg70-can" &&
      spec.transport != "pg70-fd") {
    ThrowInvalidArgument("--device=" + text + ": transport '" + spec.transport +
                         "' is not robotiq-tcp, robotiq-rtu, pg70-can or pg70-fd");
  }
  if (spec.address.empty()) ThrowInvalidArgument("--device=" + text + ": no address after '" + spec.transport + ":'");
  if (spec.transport == "robotiq-tcp") {
    const auto [host, port] = SplitLast(spec.address);
    if (host.empty()) ThrowInvalidArgument("--device=" + text + ": robotiq-tcp needs HOST:PORT");
    Integer(text, "port", port, 1, 65535);
  }
  if (spec.id.empty()) spec.id = spec.transport + "-" + std::to_string(index);
  return spec;
}

std::unique_ptr<GuardedDevice> OpenDevice(const DeviceSpec& spec, const std::string& limit_overrides,
                                          std::chrono::milliseconds timeout) {
  const std::string flag = spec.id + "=" + spec.transport + ":" + spec.address;
  if (spec.transport == "robotiq-tcp" || spec.transport == "robotiq-rtu") {
    const Limits limits = ApplyLimitOverrides(RobotiqLimits(), limit_overrides);
    const modbus::LinkTimeouts timeouts{timeout, std::min(timeout, std::chrono::milliseconds(50))};
    std::unique_ptr<modbus::ModbusTransport> link;
    if (spec.transport == "robotiq-tcp") {
      const auto [host, port] = SplitLast(spec.address);
      link = modbus::ConnectTcp({.host = host, .port = Integer(flag, "port", port, 1, 65535), .unit = 9,
                                 .timeouts = timeouts});
    } else {
      link = modbus::ConnectRtu({.device = spec.address, .timeouts = timeouts});
    }
    const std::string description = link->Describe();
    robotiq::Config config;
    config.limits = {.min_opening_mm = limits.min_opening * 1000, .max_opening_mm = limits.max_opening * 1000,
                     .min_speed_mm_s = limits.min_speed * 1000, .max_speed_mm_s = limits.max_speed * 1000,
                     .min_force_n = limits.min_force, .max_force_n = limits.max_force};
    return std::make_unique<GuardedDevice>(spec.id, "robotiq_2f85", description,
                                           MakeGripperDevice(std::make_unique<robotiq::Gripper>(std::move(link), config)),
                                           limits);
  }
  const Limits limits = ApplyLimitOverrides(Pg70Limits(), limit_overrides);
  const auto [where, module_text] = SplitLast(spec.address);
  pg70::Config config;
  config.timeout = timeout;
  if (!module_text.empty()) config.module_id = static_cast<uint8_t>(Integer(flag, "module id", module_text, 1, 255));
  std::string description;
  int fd = -1;
  if (spec.transport == "pg70-can") {
    const can_filter filters[] = {{static_cast<canid_t>(pg70::smp::kFromModule + config.module_id), CAN_SFF_MASK},
                                  {static_cast<canid_t>(pg70::smp::kErrorFromModule + config.module_id), CAN_SFF_MASK}};
    fd = can::OpenSocketCan(where, filters, 2);
    description = "socketcan " + where;
  } else {
    fd = Integer(flag, "descriptor", where, 0, 1 << 20);
    description = "fd " + where;
  }
  description += " module " + std::to_string(config.module_id);
  config.limits.max_velocity_mm_s = limits.max_speed * 1000;
  auto gripper = std::make_unique<pg70::Gripper>(std::make_unique<can::CanTransport>(fd, description), config);
  return std::make_unique<GuardedDevice>(spec.id, "schunk_pg70", description, MakeGripperDevice(std::move(gripper)),
                                         limits);
}

}  // namespace graspsim::drivers::gateway
