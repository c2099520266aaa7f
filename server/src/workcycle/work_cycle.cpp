// The work cycle's stages and its tactile force controller (the request checks and the geometry are in
// work_cycle_plan.cpp).
#include "workcycle/work_cycle.h"

#include <algorithm>
#include <cmath>

#include "core/error.h"
#include "core/format.h"

namespace graspsim {
namespace {

// Axis moves: the approach at 3/4 of the axis's rated speed, lift and move down slower so the grip's inertial
// load stays small (a 0.5 m/s² ramp adds 5 % to the object's weight).
constexpr double kApproachSpeedShare = 0.75;
constexpr double kDefaultAxisSpeed = 0.2;   // m/s when the joint gives no velocity limit
constexpr double kApproachAcceleration = 1.0;  // m/s²
constexpr double kLiftSpeed = 0.1;          // m/s
constexpr double kLiftAcceleration = 0.5;   // m/s²
constexpr double kAxisTolerance = 5e-4;     // m: a move has arrived within this
constexpr double kMoveSlack = 1.0;          // s after a move's end: lift and move down go on anyway
constexpr double kApproachSlack = 2.0;      // s after the approach's end: something blocks the gripper
constexpr double kOpenTimeout = 2.0;        // s for the fingers to open
constexpr double kFingerTolerance = 5e-4;   // m
constexpr double kCloseSpeed = 0.03;        // m/s per finger until the first contact
constexpr double kContactThreshold = 100;   // intensity counts (≈ 0.07 N): either pad above it is a contact
// The force controller: a PI from the sum error to the current limit, its gains normalised by the nominal
// plant gain (counts per ampere: intensity_per_newton · the N/A the drive puts on one pad), so they hold for any
// pad or drive. Quasi-statically S = G I, a first-order closed loop with τ = (1 + Kp)/Ki = 60 ms: slower than
// the 10 ms control period and the foam's c/k = 10 ms, so sampling and the foam add no oscillation.
constexpr double kForceKp = 0.5;
constexpr double kForceKi = 25;             // 1/s
constexpr double kMinShare = 0.25;          // of the nominal current: the grip's floor
constexpr double kBand = 0.05;              // the grasp has settled within 5 % of the set-point ...
constexpr double kBandTime = 0.2;           // ... for this long, s
constexpr double kGraspTimeout = 3.0;       // s after the first contact: lift anyway
constexpr double kReleaseTimeout = 2.0;     // s: done even if a pad still reads something

std::string Mm(double metres) { return FormatNumber(std::round(metres * 1e4) / 10) + " mm"; }

[[noreturn]] void Fail(const std::string& message) { throw Error(ErrorCode::kFailedPrecondition, message); }

}  // namespace

const char* StageName(WorkCycleStage stage) {
  switch (stage) {
    case WorkCycleStage::kApproach: return "approach";
    case WorkCycleStage::kGrasp: return "grasp";
    case WorkCycleStage::kLift: return "lift";
    case WorkCycleStage::kHold: return "hold";
    case WorkCycleStage::kMoveDown: return "move_down";
    case WorkCycleStage::kRelease: return "release";
    case WorkCycleStage::kDone: return "done";
  }
  return "unknown";
}

double WorkCycle::Move::Duration() const {
  const double distance = std::abs(to - from);
  if (distance * acceleration < speed * speed) return 2 * std::sqrt(distance / acceleration);  // triangular
  return distance / speed + speed / acceleration;
}

double WorkCycle::Move::At(double time) const {
  const double distance = std::abs(to - from), total = Duration(), t = time - start;
  if (t <= 0 || distance == 0) return from;
  if (t >= total) return to;
  const double peak = std::min(speed, acceleration * total / 2);
  const double ramp = peak / acceleration;
  double s = 0;
  if (t < ramp) {
    s = acceleration * t * t / 2;
  } else if (t > total - ramp) {
    s = distance - acceleration * (total - t) * (total - t) / 2;
  } else {
    s = acceleration * ramp * ramp / 2 + peak * (t - ramp);
  }
  return from + std::copysign(std::min(s, distance), to - from);
}

uint64_t WorkCycle::Advance(PhysicsEngine* simulation, SceneState* state, uint64_t max_steps,
                            std::vector<WorkCycleFrame>* frames) {
  if (&simulation->model() != model_.get()) {
    Fail("the scene's model changed during the work cycle (a body or robot was added or removed, or the "
         "simulation parameters were set); the cycle stopped at t = " + FormatNumber(state->time) + " s");
  }
  if (!started_) {
    Start(state);
    frames->push_back(Frame(*state));
  }
  uint64_t taken = 0;
  while (!finished_ && taken < max_steps) {
    // The axis drive's set-point moves every step; the drive's own position loop follows it.
    SetCommand(state, axis_, ActuatorMode::kPosition, move_.At(state->time + dt_), -1);
    simulation->Step(state, 1, ReadingsWanted(*state, taken + 1 == max_steps) ? PhysicsEngine::Readings::kRecord
                                                                              : PhysicsEngine::Readings::kSkip);
    ++steps_;
    ++taken;
    // The controller runs every control period; while the fingers close it also watches the pads every step
    // (a contact interrupt), so the switch to force control does not wait up to a period: at 30 mm/s a stiff
    // grip builds ~25 N in 10 ms. Force control then runs every period from the contact on. It decides before
    // the step's frame is taken, so a frame's stage is the one in force from its time on.
    const WorkCycleStage before = stage_;
    if (steps_ >= next_control_ || (stage_ == WorkCycleStage::kGrasp && !force_control_ && Touching(*state))) {
      next_control_ = steps_ + control_steps_;
      Control(state);
    }
    // Frames on the frame-rate grid, plus one at the first step of each stage (the last: "done"), so that a stage
    // shorter than a frame period (a release takes ~10 ms) still shows, and the stream says when each began.
    const bool due = state->time >= NextFrameTime() - dt_ / 2;
    if (due) ++frames_due_;
    if (due || stage_ != before) frames->push_back(Frame(*state));
    finished_ = stage_ == WorkCycleStage::kDone;
  }
  return taken;
}

bool WorkCycle::ReadingsWanted(const SceneState& state, bool last_of_call) const {
  // What reads the pads and joint wrenches after this step: the controller (every control period, and every step
  // while the fingers close), a frame, or whoever gets the state after the call (a recording, a viewer). A frame
  // is wanted a step early rather than late: the time after the step is predicted, so it may round the other way.
  if (last_of_call || steps_ + 1 >= next_control_) return true;
  if (stage_ == WorkCycleStage::kGrasp && !force_control_) return true;
  return state.time + dt_ >= NextFrameTime() - 1.5 * dt_;
}

double WorkCycle::NextFrameTime() const { return start_time_ + double(frames_due_) / request_.frame_rate_hz; }

void WorkCycle::Start(SceneState* state) {
  started_ = true;
  const double qa = state->joint_positions[axis_];
  move_ = Move{qa, qa, state->time, 1, 1};
  for (size_t joint : {axis_, finger_}) state->actuators[joint].state = DcMotorState();
  SetCommand(state, axis_, ActuatorMode::kPosition, qa, -1);
  SetCommand(state, finger_, ActuatorMode::kPosition, summary_.opening_position, -1);
  current_limit_ = finger_drive_.current_limit;
  stage_start_ = summary_.stage_start[0] = state->time;
  start_time_ = state->time;
  frames_due_ = 1;  // the frame at the start is taken by Advance
  next_control_ = control_steps_;
  Control(state);  // the descent starts at once when the fingers are open already
}

bool WorkCycle::Touching(const SceneState& state) const {
  for (size_t pad = 0; pad < pads_.size(); ++pad) {
    if (double(IntensitySum(state, pad)) > kContactThreshold) return true;
  }
  return false;
}

uint64_t WorkCycle::IntensitySum(const SceneState& state, size_t pad) const {
  ReadTactileArray(*model_, state, pads_[pad], &pad_reading_);
  return pad_reading_.intensity_sum;
}

void WorkCycle::Control(SceneState* state) {
  const SceneModel& m = *model_;
  const double t = state->time, qa = state->joint_positions[axis_], qf = state->joint_positions[finger_];
  const uint64_t left = IntensitySum(*state, 0);
  const uint64_t right = IntensitySum(*state, 1);
  const double mean = (double(left) + double(right)) / 2;
  const double setpoint = request_.tactile_setpoint;
  const std::string& gripper = request_.gripper_id;
  switch (stage_) {
    case WorkCycleStage::kApproach: {
      if (!descending_) {
        if (qf >= summary_.opening_position - kFingerTolerance) {
          const JointSpec& axis = m.joints[axis_];
          const double rated = axis.velocity_limit > 0 ? axis.velocity_limit : kDefaultAxisSpeed;
          move_ = Move{qa, summary_.grasp_position, t, kApproachSpeedShare * rated, kApproachAcceleration};
          descending_ = true;
        } else if (t - stage_start_ > kOpenTimeout) {
          Fail("approach: the fingers of '" + gripper + "' opened to only " + FormatNumber(qf) + " m of " +
               FormatNumber(summary_.opening_position) + " m in " + FormatNumber(kOpenTimeout) + " s");
        }
      } else if (t >= move_.start + move_.Duration()) {
        if (std::abs(qa - move_.to) < kAxisTolerance) {
          Enter(WorkCycleStage::kGrasp, state);
        } else if (t > move_.start + move_.Duration() + kApproachSlack) {
          Fail("approach: '" + m.joints[axis_].id + "' stopped at " + FormatNumber(qa) + " m, " +
               Mm(std::abs(qa - move_.to)) + " from the grasp height; something blocks the gripper");
        }
      }
      break;
    }
    case WorkCycleStage::kGrasp:
      if (!force_control_) {
        if (double(std::max(left, right)) > kContactThreshold) {
          summary_.first_contact_time = t;
          force_control_ = true;
          integral_ = request_.tactile_setpoint * amps_per_count_;  // the nominal current (see ForceControl)
          ForceControl(state, mean);
        } else if (qf <= m.joints[finger_].lower + kFingerTolerance ||
                   t - stage_start_ > summary_.opening_position / kCloseSpeed + 1) {
          Fail("grasp: the fingers of '" + gripper + "' closed to " + FormatNumber(qf) + " m without touching '" +
               request_.object_id + "'");
        }
        break;
      }
      ForceControl(state, mean);
      band_since_ = std::abs(mean - setpoint) <= kBand * setpoint ? (band_since_ < 0 ? t : band_since_) : -1;
      if (band_since_ >= 0 && t - band_since_ >= kBandTime - dt_ / 2) {
        summary_.settled = true;
        Enter(WorkCycleStage::kLift, state);
      } else if (t - summary_.first_contact_time >= kGraspTimeout) {
        Enter(WorkCycleStage::kLift, state);
      }
      break;
    case WorkCycleStage::kLift:
      ForceControl(state, mean);
      if (MoveFinished(*state)) Enter(WorkCycleStage::kHold, state);
      break;
    case WorkCycleStage::kHold:
      ForceControl(state, mean);
      if (t - stage_start_ >= request_.hold_time - dt_ / 2) Enter(WorkCycleStage::kMoveDown, state);
      break;
    case WorkCycleStage::kMoveDown:
      ForceControl(state, mean);
      if (MoveFinished(*state)) Enter(WorkCycleStage::kRelease, state);
      break;
    case WorkCycleStage::kRelease:
      if ((left == 0 && right == 0) || t - stage_start_ >= kReleaseTimeout) Enter(WorkCycleStage::kDone, state);
      break;
    case WorkCycleStage::kDone:
      break;
  }
}

void WorkCycle::Enter(WorkCycleStage stage, SceneState* state) {
  const double t = state->time;
  stage_ = stage;
  stage_start_ = summary_.stage_start[static_cast<size_t>(stage)] = t;
  switch (stage) {
    case WorkCycleStage::kGrasp:
      // Velocity control until the first contact, at the drive's own current limit; the loop starts afresh.
      state->actuators[finger_].state = DcMotorState();
      SetCommand(state, finger_, ActuatorMode::kVelocity, -kCloseSpeed, -1);
      break;
    case WorkCycleStage::kLift:
      move_ = Move{summary_.grasp_position, summary_.grasp_position + lift_position_, t, kLiftSpeed,
                   kLiftAcceleration};
      break;
    case WorkCycleStage::kMoveDown:
      move_ = Move{move_.to, summary_.grasp_position, t, kLiftSpeed, kLiftAcceleration};
      break;
    case WorkCycleStage::kRelease:
      force_control_ = false;
      current_limit_ = finger_drive_.current_limit;
      state->actuators[finger_].state = DcMotorState();
      SetCommand(state, finger_, ActuatorMode::kPosition, summary_.opening_position, -1);
      break;
    default:
      break;
  }
}

void WorkCycle::ForceControl(SceneState* state, double mean_sum) {
  // PI from the sum error to the finger drive's current limit. The integral starts at the nominal current
  // I0 = set-point / (counts per ampere), so at the contact the limit already allows the set-point's force and
  // the fingers close on at the commanded speed until the foam pushes back that hard: the rise is set by the
  // contact's stiffness (the paper's coverage effect), and the PI only corrects what the nominal gain misses
  // (saturated texels, friction). Conditional integration: the integral grows only while the limit is what
  // holds the finger (motor current at it); while the finger still closes at the commanded speed the force is
  // set by the foam, and integrating would only wind up. The limit never drops below I0/4, so a transient (the
  // foam's damping spike at impact) cannot open the grip.
  const double nominal = request_.tactile_setpoint * amps_per_count_;
  const double error = request_.tactile_setpoint - mean_sum;
  const double period = control_steps_ * dt_;
  const auto actuator = state->actuators.find(finger_);
  const double current = actuator == state->actuators.end() ? 0 : std::abs(actuator->second.state.current);
  const bool holding = current >= 0.98 * current_limit_;
  if (error < 0 || holding) {
    integral_ = std::clamp(integral_ + kForceKi * period * error * amps_per_count_, 0.0, current_cap_);
  }
  current_limit_ = std::clamp(kForceKp * error * amps_per_count_ + integral_, kMinShare * nominal, current_cap_);
  SetCommand(state, finger_, ActuatorMode::kVelocity, -kCloseSpeed, current_limit_);
}

bool WorkCycle::MoveFinished(const SceneState& state) const {
  const double end = move_.start + move_.Duration();
  if (state.time < end) return false;
  return std::abs(state.joint_positions[axis_] - move_.to) < kAxisTolerance || state.time >= end + kMoveSlack;
}

void WorkCycle::SetCommand(SceneState* state, size_t joint, ActuatorMode mode, double value,
                           double current_limit) const {
  // The motor is (re)installed every time, so a SetActuators between chunks cannot leave a joint undriven.
  JointActuator& actuator = state->actuators[joint];
  actuator.motor = joint == axis_ ? axis_drive_ : finger_drive_;
  actuator.command.mode = mode;
  actuator.command.value = value;
  actuator.command.current_limit = current_limit;
}

WorkCycleFrame WorkCycle::Frame(const SceneState& state) const {
  const SceneModel& m = *model_;
  WorkCycleFrame frame;
  frame.stage = stage_;
  frame.time = state.time;
  for (size_t i = 0; i < 2; ++i) frame.pads[i] = ReadTactileArray(m, state, pads_[i]);
  frame.gripper = ReadGripper(m, state, m.robots[robot_]);
  frame.object_pose = state.body_poses[object_];
  frame.axis_position = state.joint_positions[axis_];
  frame.current_limit = force_control_ ? current_limit_ : finger_drive_.current_limit;
  return frame;
}

}  // namespace graspsim
