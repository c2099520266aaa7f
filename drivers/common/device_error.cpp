#include "drivers/common/device_error.h"

#include <cmath>
#include <sstream>

namespace graspsim::drivers {

const char* DeviceFailureName(DeviceFailure failure) {
  switch (failure) {
    case DeviceFailure::kTimeout: return "timeout";
    case DeviceFailure::kMalformedFrame: return "malformed frame";
    case DeviceFailure::kDeviceException: return "device exception";
    case DeviceFailure::kDeviceFault: return "device fault";
    case DeviceFailure::kIo: return "i/o error";
  }
  return "unknown";
}

void ThrowOutOfRange(const std::string& field, double value, double low, double high) {
  std::ostringstream message;
  message << field << ": " << value << " is outside [" << low << ", " << high << "]";
  ThrowInvalidArgument(message.str());
}

void CheckInRange(const std::string& field, double value, double low, double high) {
  // NaN fails both comparisons, so it is rejected too.
  if (!(value >= low && value <= high)) ThrowOutOfRange(field, value, low, high);
}

void CheckAboveAtMost(const std::string& field, double value, double low, double high) {
  if (!(value > low && value <= high)) {
    std::ostringstream message;
    message << field << ": " << value << " is outside (" << low << ", " << high << "]";
    ThrowInvalidArgument(message.str());
  }
}

}  // namespace graspsim::drivers
