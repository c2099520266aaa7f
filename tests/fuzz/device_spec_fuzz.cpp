// The gateway's --device and limit-override flags (drivers/gateway/device_spec.h ParseDeviceSpec,
// guarded_device.h ApplyLimitOverrides): the input up to the first newline is a --device value, the rest a
// "name=value,..." override list applied to each gripper's native limits. Overrides may only narrow the limits.
#include "drivers/gateway/device_spec.h"
#include "drivers/gateway/guarded_device.h"
#include "fuzz_common.h"

namespace gw = graspsim::drivers::gateway;

namespace {

void CheckNarrowed(const gw::Limits& native, const gw::Limits& out) {
  const auto inside = [](double lo, double hi, double value) { return value >= lo && value <= hi; };
  if (!inside(native.min_opening, native.max_opening, out.min_opening) ||
      !inside(native.min_opening, native.max_opening, out.max_opening) ||
      !inside(native.min_speed, native.max_speed, out.min_speed) ||
      !inside(native.min_speed, native.max_speed, out.max_speed) ||
      !inside(native.min_force, native.max_force, out.min_force) ||
      !inside(native.min_force, native.max_force, out.max_force)) {
    graspsim::fuzz::Broken("ApplyLimitOverrides: a limit outside the native range");
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string text = graspsim::fuzz::Text(data, size);
  const size_t newline = text.find('\n');
  const std::string spec = text.substr(0, newline);
  const std::string overrides = newline == std::string::npos ? "" : text.substr(newline + 1);
  graspsim::fuzz::Rejects([&] {
    const gw::DeviceSpec parsed = gw::ParseDeviceSpec(spec, 0);
    if (parsed.id.empty() || parsed.address.empty()) graspsim::fuzz::Broken("ParseDeviceSpec: empty id or address");
  });
  for (const gw::Limits& native : {gw::RobotiqLimits(), gw::Pg70Limits()}) {
    graspsim::fuzz::Rejects([&] { CheckNarrowed(native, gw::ApplyLimitOverrides(native, overrides)); });
  }
  return 0;
}
