#include "gateway/simulated_gripper.h"

#include <algorithm>
#include <cmath>

#include "core/error.h"
#include "physics/builtin_drives.h"
#include "sensors/readings.h"
#include "tactile/tactile_frame.h"

namespace graspsim::gateway {
namespace {

constexpr double kNewtonPerAmp = 200.0 / 3.5;  // PG70: 200 N at its rated 3.5 A (physics/actuators.cpp)
constexpr double kMovingSpeed = 1e-4;          // m/s of a finger: slower counts as stopped

}  // namespace

SimulatedGripper::SimulatedGripper(std::shared_ptr<const SceneModel> model, SceneState state,
                                   const std::string& gripper_id)
    : model_(std::move(model)), simulation_(model_), state_(std::move(state)), gripper_id_(gripper_id) {
  const auto robot = model_->robot_index.find(gripper_id);
  if (robot == model_->robot_index.end()) ThrowNotFound("gripper_id: no robot '" + gripper_id + "' in the scene");
  robot_ = robot->second;
  const auto finger = model_->joint_index.find(gripper_id + "/finger_left_joint");
  if (finger == model_->joint_index.end() || model_->joints[finger->second].type != JointType::kPrismatic) {
    ThrowInvalidArgument("gripper_id: robot '" + gripper_id +
                         "' has no prismatic joint 'finger_left_joint' (a built-in PG70 has)");
  }
  finger_ = finger->second;
  simulation_.PrepareState(&state_);
  start_time_ = state_.time;
}

void SimulatedGripper::SetOpening(double opening_m) {
  const JointSpec& joint = model_->joints[finger_];
  const double q = std::clamp(opening_m / 2, joint.lower, joint.upper);
  // The driving finger and every finger that mimics it.
  for (const std::string& id : model_->robots[robot_].joint_ids) {
    const size_t index = model_->joint_index.at(id);
    const JointSpec& other = model_->joints[index];
    if (index == finger_ || (other.mimic && other.mimic->joint_id == joint.id)) {
      state_.joint_positions[index] = q;
      state_.joint_velocities[index] = 0;
    }
  }
  state_.actuators[finger_].state = DcMotorState();
}

void SimulatedGripper::MoveTo(double opening_m, double speed_m_s, double force_n) {
  JointActuator& actuator = state_.actuators[finger_];
  actuator.motor = BuiltinDrive(model_->robots[robot_], model_->joints[finger_]);
  actuator.motor.max_velocity = std::min(actuator.motor.max_velocity, speed_m_s / 2);
  actuator.command.mode = ActuatorMode::kPosition;
  actuator.command.value = opening_m / 2;
  actuator.command.current_limit = std::min(actuator.motor.current_limit, force_n / kNewtonPerAmp);
}

void SimulatedGripper::Stop() {
  JointActuator& actuator = state_.actuators[finger_];
  actuator.command.mode = ActuatorMode::kVelocity;
  actuator.command.value = 0;
}

drivers::GripperReading SimulatedGripper::Read() {
  const GripperReading g = ReadGripper(*model_, state_, model_->robots[robot_]);
  drivers::GripperReading reading;
  reading.opening_m = g.finger_distance;
  reading.current_a = std::abs(g.motor_current);
  reading.moving = std::abs(g.finger_velocity) > kMovingSpeed;
  reading.object_detected = !reading.moving && TactileSum() > 0;
  return reading;
}

void SimulatedGripper::AdvanceTo(double seconds) {
  // Whole steps up to the requested time (never past it): the twin never runs ahead of the real device.
  const double dt = model_->simulation.time_step;
  const int steps = static_cast<int>(std::floor((start_time_ + seconds - state_.time) / dt + 1e-9));
  if (steps > 0) simulation_.Step(&state_, steps);
}

double SimulatedGripper::TactileSum() const {
  double sum = 0;
  for (const std::string& pad : model_->robots[robot_].tactile_array_ids) {
    sum += static_cast<double>(ReadTactileArray(*model_, state_, model_->tactile_index.at(pad)).intensity_sum);
  }
  return sum;
}

}  // namespace graspsim::gateway
