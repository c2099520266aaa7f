// The values the gateway hub relays, in plain C++ (rpc/convert_gateway.cpp maps them to and from
// graspsim.v1 gateway messages). Units SI: m, m/s, N, A, s.
#pragma once

#include <cstdint>
#include <optional>
#include <string>

namespace graspsim::gateway {

// Canonical status codes (google.rpc.Code, the same numbers as gRPC's) of a failed command: a gateway reports
// them and the server returns them as is, so the hub needs no gRPC.
enum class Code : int {
  kOk = 0,
  kInvalidArgument = 3,
  kDeadlineExceeded = 4,
  kNotFound = 5,
  kFailedPrecondition = 9,
  kInternal = 13,
  kUnavailable = 14,
};

struct DeviceLimits {
  double min_opening = 0, max_opening = 0;  // m
  double min_speed = 0, max_speed = 0;      // m/s
  double min_force = 0, max_force = 0;      // N
  double max_current = 0;                   // A
};

struct DeviceReading {
  std::string device_id;
  double time = 0;          // s, the gateway's clock (Unix time)
  double opening = 0;       // m
  double current = 0;       // A
  bool moving = false, object_detected = false, estopped = false;
  std::string fault{};
};

struct DeviceInfo {
  std::string id, kind, gateway, link;
  DeviceLimits limits{};
  std::optional<DeviceReading> last_reading{};
};

struct Move {
  double opening = 0, speed = 0, force = 0;
};

struct Command {
  enum class Kind { kMoveTo, kVelocity, kMaxForce, kStop, kInitialize, kEstop, kMove, kRead };
  std::string device_id;
  uint64_t id = 0;       // the hub assigns it
  Kind kind = Kind::kRead;
  double value = 0;      // kMoveTo m, kVelocity m/s, kMaxForce N
  Move move;             // kMove
  double timeout = 0;    // s; 0 = the hub's default
};

struct CommandResult {
  uint64_t command_id = 0;
  Code code = Code::kOk;
  std::string message;
  std::optional<DeviceReading> reading;
  double gateway_seconds = 0;
  bool ok() const { return code == Code::kOk; }
};

}  // namespace graspsim::gateway
