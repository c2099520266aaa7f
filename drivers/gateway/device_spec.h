// The gateway's --device flags: which gripper, on which link, under which id.
//   [ID=]robotiq-tcp:HOST:PORT     Robotiq 2F-85, Modbus TCP, unit 9
//   [ID=]robotiq-rtu:DEVICE        Robotiq 2F-85, Modbus RTU 115200 8N1, unit 9 (e.g. /dev/ttyUSB0, a pty)
//   [ID=]pg70-can:IFACE[:MODULE]   Schunk PG70, SMP over SocketCAN (module id default 12)
//   [ID=]pg70-fd:FD[:MODULE]       Schunk PG70, SMP over an inherited descriptor carrying can_frame packets
//                                  (a socketpair end: tests and the demo, where the machine has no CAN)
// Without ID= the id is "<transport>-<index>", e.g. "robotiq-tcp-0".
#pragma once

#include <chrono>
#include <memory>
#include <string>

#include "drivers/gateway/guarded_device.h"

namespace graspsim::drivers::gateway {

struct DeviceSpec {
  std::string id;
  std::string transport;  // robotiq-tcp, robotiq-rtu, pg70-can, pg70-fd
  std::string address;    // everything after "<transport>:"
};

// Throws Error(kInvalidArgument) naming the flag for an unknown transport or a malformed address.
DeviceSpec ParseDeviceSpec(const std::string& text, int index);

// Opens the link and the driver, and wraps it with the native limits narrowed by `limit_overrides`
// (ApplyLimitOverrides). `timeout` bounds every answer of the device. Does not initialise the gripper.
std::unique_ptr<GuardedDevice> OpenDevice(const DeviceSpec& spec, const std::string& limit_overrides,
                                          std::chrono::milliseconds timeout);

}  // namespace graspsim::drivers::gateway
