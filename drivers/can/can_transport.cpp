#include "drivers/can/can_transport.h"

#include <linux/can/raw.h>
#include <net/if.h>
#include <poll.h>
#include <sys/ioctl.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

#include "drivers/common/device_error.h"

namespace graspsim::drivers::can {
namespace {

[[noreturn]] void ThrowIo(const std::string& name, const std::string& what, int error) {
  throw DeviceError(DeviceFailure::kIo, name + ": " + what + ": " + std::strerror(error));
}

}  // namespace

CanTransport::CanTransport(int fd, std::string name) : fd_(fd), name_(std::move(name)) {}

CanTransport::~CanTransport() {
  if (fd_ >= 0) close(fd_);
}

void CanTransport::Send(const can_frame& frame) {
  ssize_t sent;
  do {
    sent = write(fd_, &frame, sizeof(frame));
  } while (sent < 0 && errno == EINTR);
  if (sent != static_cast<ssize_t>(sizeof(frame))) ThrowIo(name_, "send", sent < 0 ? errno : EMSGSIZE);
}

std::optional<can_frame> CanTransport::Receive(std::chrono::milliseconds timeout) {
  pollfd pfd{fd_, POLLIN, 0};
  int ready;
  do {
    ready = poll(&pfd, 1, static_cast<int>(timeout.count()));
  } while (ready < 0 && errno == EINTR);
  if (ready < 0) ThrowIo(name_, "poll", errno);
  if (ready == 0) return std::nullopt;
  can_frame frame{};
  const ssize_t got = read(fd_, &frame, sizeof(frame));
  if (got == 0) throw DeviceError(DeviceFailure::kIo, name_ + ": link closed by the other end");
  if (got < 0) ThrowIo(name_, "receive", errno);
  if (got != static_cast<ssize_t>(sizeof(frame)) || frame.can_dlc > CAN_MAX_DLEN) {
    throw DeviceError(DeviceFailure::kMalformedFrame, name_ + ": received " + std::to_string(got) +
                                                          " bytes with dlc " + std::to_string(frame.can_dlc) +
                                                          ", not a classical CAN frame");
  }
  return frame;
}

int OpenSocketCan(const std::string& interface, const can_filter* filters, int filter_count) {
  const std::string name = "socketcan " + interface;
  const int fd = socket(PF_CAN, SOCK_RAW, CAN_RAW);
  if (fd < 0) ThrowIo(name, "socket", errno);
  ifreq request{};
  std::strncpy(request.ifr_name, interface.c_str(), IFNAMSIZ - 1);
  if (ioctl(fd, SIOCGIFINDEX, &request) < 0) {
    const int error = errno;
    close(fd);
    ThrowIo(name, "no such interface", error);
  }
  if (filter_count > 0) {
    setsockopt(fd, SOL_CAN_RAW, CAN_RAW_FILTER, filters, static_cast<socklen_t>(sizeof(can_filter) * filter_count));
  }
  sockaddr_can address{};
  address.can_family = AF_CAN;
  address.can_ifindex = request.ifr_ifindex;
  if (bind(fd, reinterpret_cast<sockaddr*>(&address), sizeof(address)) < 0) {
    const int error = errno;
    close(fd);
    ThrowIo(name, "bind", error);
  }
  return fd;
}

}  // namespace graspsim::drivers::can
