// Errors of the device-driver layer. Limits are checked before anything is sent and throw graspsim::Error with
// kInvalidArgument (core/error.h), naming the field and the value. Everything that goes wrong on the wire throws
// DeviceError: its failure() says what happened, so the gateway can map a timeout to UNAVAILABLE and a device
// fault to FAILED_PRECONDITION without parsing messages. Each device call that throws has already tried to leave
// the device stopped; the message says whether that stop was delivered.
#pragma once

#include <string>

#include "core/error.h"

namespace graspsim::drivers {

enum class DeviceFailure {
  kTimeout,          // no (complete) answer within the configured time
  kMalformedFrame,   // an answer arrived but does not parse: bad CRC, wrong count, bad fragment sequence
  kDeviceException,  // the device refused the request (Modbus exception, SMP error message)
  kDeviceFault,      // the device reports a fault in its status (e.g. Robotiq gFLT)
  kIo,               // the transport itself failed (connect, read, write)
};

const char* DeviceFailureName(DeviceFailure failure);

class DeviceError : public Error {
 public:
  DeviceError(DeviceFailure failure, const std::string& message)
      : Error(ErrorCode::kFailedPrecondition, message), failure_(failure) {}
  DeviceFailure failure() const { return failure_; }

 private:
  DeviceFailure failure_;
};

// A number of a limit check, e.g. "move.position_mm: 90 is outside [0, 85]".
[[noreturn]] void ThrowOutOfRange(const std::string& field, double value, double low, double high);
void CheckInRange(const std::string& field, double value, double low, double high);
// low < value <= high, e.g. a speed that must not be 0: "move_position.velocity_mm_s: 0 is outside (0, 82]".
void CheckAboveAtMost(const std::string& field, double value, double low, double high);

}  // namespace graspsim::drivers
