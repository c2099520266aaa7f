#include "drivers/gateway/guarded_device.h"

#include <cmath>
#include <cstdio>
#include <sstream>

#include "core/error.h"

namespace graspsim::drivers::gateway {
namespace {

std::string Number(double value) {
  char text[32];
  std::snprintf(text, sizeof(text), "%.6g", value);
  return text;
}

double* Field(Limits& limits, const std::string& name) {
  if (name == "min_opening") return &limits.min_opening;
  if (name == "max_opening") return &limits.max_opening;
  if (name == "min_speed") return &limits.min_speed;
  if (name == "max_speed") return &limits.max_speed;
  if (name == "min_force") return &limits.min_force;
  if (name == "max_force") return &limits.max_force;
  if (name == "max_current") return &limits.max_current;
  return nullptr;
}

}  // namespace

Limits RobotiqLimits() {
  // robotiq::Limits in SI; gCU counts 10 mA, so 2.55 A is the largest current the status can report.
  return {.min_opening = 0, .max_opening = 0.085, .min_speed = 0.020, .max_speed = 0.150,
          .min_force = 20, .max_force = 235, .max_current = 2.55};
}

Limits Pg70Limits() {
  // pg70::Limits in SI: 70 mm stroke, 82 mm/s; the force is the 3.5 A current limit at 57 N/A (gripper_device.h).
  // The PG70 refuses a zero speed or current, so the minimums are small positive values.
  return {.min_opening = 0, .max_opening = 0.070, .min_speed = 0.001, .max_speed = 0.082,
          .min_force = 1, .max_force = 3.5 * 57.0, .max_current = 3.5};
}

Limits ApplyLimitOverrides(const Limits& native, const std::string& overrides) {
  Limits limits = native;
  std::stringstream entries(overrides);
  std::string entry;
  while (std::getline(entries, entry, ',')) {
    if (entry.empty()) continue;
    const size_t eq = entry.find('=');
    double* field = eq == std::string::npos ? nullptr : Field(limits, entry.substr(0, eq));
    if (field == nullptr) {
      ThrowInvalidArgument("--limits: '" + entry + "' is not name=value with a name of min_opening, max_opening, " +
                           "min_speed, max_speed, min_force, max_force, max_current");
    }
    double value = 0;
    try {
      value = std::stod(entry.substr(eq + 1));
    } catch (const std::exception&) {
      ThrowInvalidArgument("--limits: '" + entry + "' has no number");
    }
    Limits native_copy = native;
    const std::string name = entry.substr(0, eq);
    const double bound = *Field(native_copy, name);
    const bool is_min = name.rfind("min_", 0) == 0;
    const bool inside = is_min ? value >= bound : value <= bound && value > 0;
    if (!std::isfinite(value) || !inside) {
      ThrowInvalidArgument("--limits: " + name + "=" + Number(value) + " is outside the device's own " +
                           (is_min ? "minimum " : "maximum ") + Number(bound));
    }
    *field = value;
  }
  if (limits.min_opening >= limits.max_opening || limits.min_speed > limits.max_speed ||
      limits.min_force > limits.max_force) {
    ThrowInvalidArgument("--limits: '" + overrides + "' leaves an empty range (a minimum above its maximum)");
  }
  return limits;
}

GuardedDevice::GuardedDevice(std::string id, std::string kind, std::string link, std::unique_ptr<GripperDevice> device,
                             Limits limits)
    : id_(std::move(id)),
      kind_(std::move(kind)),
      link_(std::move(link)),
      device_(std::move(device)),
      limits_(limits),
      speed_(std::max(limits.min_speed, 0.5 * limits.max_speed)),
      force_(limits.min_force) {}

void GuardedDevice::CheckMove(double opening, double speed, double force) const {
  auto check = [&](const char* field, double value, double low, double high, const char* unit) {
    if (std::isfinite(value) && value >= low && value <= high) return;
    ThrowInvalidArgument(std::string(field) + ": " + Number(value) + " " + unit + " is outside the limits [" +
                         Number(low) + ", " + Number(high) + "] of device '" + id_ + "'");
  };
  check("move.opening", opening, limits_.min_opening, limits_.max_opening, "m");
  check("move.speed", speed, limits_.min_speed, limits_.max_speed, "m/s");
  check("move.force", force, limits_.min_force, limits_.max_force, "N");
  if (estopped_) {
    throw Error(ErrorCode::kFailedPrecondition,
                "device '" + id_ + "' is e-stopped: send 'initialize' before moving it again");
  }
}

void GuardedDevice::Move(double opening, double speed, double force) {
  std::lock_guard<std::mutex> lock(mutex_);
  CheckMove(opening, speed, force);
  device_->MoveTo(opening, speed, force);
}

void GuardedDevice::MoveTo(double opening) {
  std::lock_guard<std::mutex> lock(mutex_);
  CheckMove(opening, speed_, force_);
  device_->MoveTo(opening, speed_, force_);
}

void GuardedDevice::SetSpeed(double speed) {
  std::lock_guard<std::mutex> lock(mutex_);
  if (!(std::isfinite(speed) && speed >= limits_.min_speed && speed <= limits_.max_speed)) {
    ThrowInvalidArgument("velocity: " + Number(speed) + " m/s is outside the limits [" + Number(limits_.min_speed) +
                         ", " + Number(limits_.max_speed) + "] of device '" + id_ + "'");
  }
  speed_ = speed;
}

void GuardedDevice::SetForce(double force) {
  std::lock_guard<std::mutex> lock(mutex_);
  if (!(std::isfinite(force) && force >= limits_.min_force && force <= limits_.max_force)) {
    ThrowInvalidArgument("max_force: " + Number(force) + " N is outside the limits [" + Number(limits_.min_force) +
                         ", " + Number(limits_.max_force) + "] of device '" + id_ + "'");
  }
  force_ = force;
}

void GuardedDevice::Stop() {
  std::lock_guard<std::mutex> lock(mutex_);
  device_->Stop();
}

void GuardedDevice::EmergencyStop() {
  std::lock_guard<std::mutex> lock(mutex_);
  estopped_ = true;  // before the stop: a failed stop must not leave the device accepting moves
  device_->Stop();
}

void GuardedDevice::Initialize() {
  std::lock_guard<std::mutex> lock(mutex_);
  device_->Initialize();
  estopped_ = false;
}

GripperReading GuardedDevice::Read() {
  std::lock_guard<std::mutex> lock(mutex_);
  return device_->Read();
}

bool GuardedDevice::estopped() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return estopped_;
}

}  // namespace graspsim::drivers::gateway
