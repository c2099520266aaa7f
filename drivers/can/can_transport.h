// A CAN link carrying classical frames (struct can_frame) over any file descriptor: a SocketCAN raw socket on the
// robot PC, or one end of a socketpair(AF_UNIX, SOCK_SEQPACKET) in tests (one packet per frame, as a raw CAN
// socket delivers them). The transport owns the descriptor.
#pragma once

#include <linux/can.h>

#include <chrono>
#include <optional>
#include <string>

namespace graspsim::drivers::can {

class CanTransport {
 public:
  CanTransport(int fd, std::string name);
  ~CanTransport();
  CanTransport(const CanTransport&) = delete;
  CanTransport& operator=(const CanTransport&) = delete;

  // Throws DeviceError(kIo) when the descriptor refuses the frame.
  void Send(const can_frame& frame);
  // The next frame, or nullopt when none arrives within `timeout`. Throws DeviceError(kIo) on a closed link and
  // DeviceError(kMalformedFrame) on a packet that is not a can_frame with dlc <= 8.
  std::optional<can_frame> Receive(std::chrono::milliseconds timeout);

  const std::string& name() const { return name_; }
  int fd() const { return fd_; }

 private:
  int fd_;
  std::string name_;
};

// A raw SocketCAN socket bound to `interface` (e.g. "can0") that receives only what the filters pass (for a PG70:
// 0x700 + id and 0x300 + id). Returns the descriptor for CanTransport; throws DeviceError(kIo) if the interface
// does not exist or the socket cannot be bound.
int OpenSocketCan(const std::string& interface, const can_filter* filters, int filter_count);

}  // namespace graspsim::drivers::can
