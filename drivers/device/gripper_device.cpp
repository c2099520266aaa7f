#include "drivers/device/gripper_device.h"

#include "drivers/pg70/pg70_gripper.h"
#include "drivers/robotiq/robotiq_gripper.h"

namespace graspsim::drivers {
namespace {

constexpr double kMmPerM = 1000.0;

class RobotiqDevice : public GripperDevice {
 public:
  explicit RobotiqDevice(std::unique_ptr<robotiq::Gripper> gripper) : gripper_(std::move(gripper)) {}
  std::string Name() const override { return "robotiq 2f-85 on " + gripper_->link().Describe(); }
  void Initialize() override { gripper_->Activate(); }
  void MoveTo(double opening_m, double speed_m_s, double force_n) override {
    gripper_->Move(opening_m * kMmPerM, speed_m_s * kMmPerM, force_n);
  }
  void Stop() override { gripper_->Stop(); }
  GripperReading Read() override {
    const robotiq::Reading r = gripper_->ReadStatus();
    return {.opening_m = r.opening_mm / kMmPerM,
            .current_a = r.current_ma / 1000.0,
            .moving = r.moving,
            .object_detected = r.object_detected,
            .fault = r.fault == robotiq::kFaultNone ? "" : r.fault_name};
  }

 private:
  std::unique_ptr<robotiq::Gripper> gripper_;
};

class Pg70Device : public GripperDevice {
 public:
  Pg70Device(std::unique_ptr<pg70::Gripper> gripper, double newton_per_amp)
      : gripper_(std::move(gripper)), newton_per_amp_(newton_per_amp) {}
  std::string Name() const override { return "schunk pg70 module " + std::to_string(gripper_->config().module_id); }
  void Initialize() override { gripper_->Reference(); }
  void MoveTo(double opening_m, double speed_m_s, double force_n) override {
    // The full acceleration the limits allow: the PG70's profile, not the caller, shapes the start of a move.
    gripper_->MovePosition(opening_m * kMmPerM, speed_m_s * kMmPerM, gripper_->config().limits.max_acceleration_mm_s2,
                           force_n / newton_per_amp_);
  }
  void Stop() override { gripper_->Stop(); }
  GripperReading Read() override {
    const pg70::smp::State s = gripper_->GetState();
    const bool moving = (s.flags & pg70::smp::state::kMoving) != 0;
    const bool reached = (s.flags & pg70::smp::state::kPositionReached) != 0;
    return {.opening_m = s.position_mm / kMmPerM,
            .current_a = s.current_a,
            .moving = moving,
            // Stopped short of the target while still drawing current: the fingers are pressing on something.
            .object_detected = !moving && !reached && s.current_a > 0.0f,
            .fault = s.error_code == 0 ? "" : pg70::smp::ErrorName(s.error_code)};
  }

 private:
  std::unique_ptr<pg70::Gripper> gripper_;
  double newton_per_amp_;
};

}  // namespace

std::unique_ptr<GripperDevice> MakeGripperDevice(std::unique_ptr<robotiq::Gripper> gripper) {
  return std::make_unique<RobotiqDevice>(std::move(gripper));
}

std::unique_ptr<GripperDevice> MakeGripperDevice(std::unique_ptr<pg70::Gripper> gripper, double newton_per_amp) {
  return std::make_unique<Pg70Device>(std::move(gripper), newton_per_amp);
}

}  // namespace graspsim::drivers
