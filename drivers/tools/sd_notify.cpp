#include "drivers/tools/sd_notify.h"

#include <sys/socket.h>
#include <sys/un.h>
#include <unistd.h>

#include <cerrno>
#include <cstddef>
#include <cstdlib>
#include <cstring>
#include <string>

namespace graspsim::drivers::sdnotify {
namespace {

// A whole-string unsigned decimal, as systemd writes WATCHDOG_USEC and WATCHDOG_PID; false otherwise.
bool ParseUnsigned(const char* text, uint64_t* value) {
  if (text == nullptr || *text < '0' || *text > '9') return false;
  errno = 0;
  char* end = nullptr;
  const unsigned long long parsed = std::strtoull(text, &end, 10);
  if (errno != 0 || *end != '\0') return false;
  *value = parsed;
  return true;
}

}  // namespace

bool Notify(std::string_view state) {
  const char* socket_name = std::getenv("NOTIFY_SOCKET");
  if (socket_name == nullptr || socket_name[0] == '\0') return false;
  const size_t length = std::strlen(socket_name);
  sockaddr_un address{};
  address.sun_family = AF_UNIX;
  // sun_path needs no terminating NUL when the length is passed: an abstract name may use every byte.
  if ((socket_name[0] != '/' && socket_name[0] != '@') || length > sizeof(address.sun_path)) {
    errno = EINVAL;
    return false;
  }
  std::memcpy(address.sun_path, socket_name, length);
  if (socket_name[0] == '@') address.sun_path[0] = '\0';  // abstract namespace
  const int fd = socket(AF_UNIX, SOCK_DGRAM | SOCK_CLOEXEC, 0);
  if (fd < 0) return false;
  const socklen_t address_length = static_cast<socklen_t>(offsetof(sockaddr_un, sun_path) + length);
  ssize_t sent;
  do {
    sent = sendto(fd, state.data(), state.size(), MSG_NOSIGNAL, reinterpret_cast<const sockaddr*>(&address),
                  address_length);
  } while (sent < 0 && errno == EINTR);
  const int saved = errno;
  close(fd);
  errno = saved;
  return sent == static_cast<ssize_t>(state.size());
}

std::chrono::microseconds WatchdogInterval() {
  uint64_t usec = 0, pid = 0;
  if (!ParseUnsigned(std::getenv("WATCHDOG_USEC"), &usec) || usec == 0) return std::chrono::microseconds(0);
  // A WATCHDOG_PID of another process: the variables were inherited, the watchdog is not ours.
  if (const char* text = std::getenv("WATCHDOG_PID"); text != nullptr && *text != '\0') {
    if (!ParseUnsigned(text, &pid) || pid != static_cast<uint64_t>(getpid())) return std::chrono::microseconds(0);
  }
  return std::chrono::microseconds(static_cast<int64_t>(usec));
}

WatchdogPinger::WatchdogPinger(std::chrono::microseconds interval) : half_(interval / 2) {}

void WatchdogPinger::Ping() {
  if (!enabled()) return;
  const int64_t now = std::chrono::duration_cast<std::chrono::nanoseconds>(
                          std::chrono::steady_clock::now().time_since_epoch())
                          .count();
  int64_t last = last_ns_.load();
  if (last != INT64_MIN && now - last < half_.count()) return;
  if (!last_ns_.compare_exchange_strong(last, now)) return;  // another thread pinged just now
  Notify("WATCHDOG=1");
}

}  // namespace graspsim::drivers::sdnotify
