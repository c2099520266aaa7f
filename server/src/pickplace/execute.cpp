// Pick and place, execution: the planned motions run in the dynamic simulation (physics/simulation.h) on a copy
// of the scene state. The arm's joints get DC-motor drives in velocity mode, commanded every step with the
// trajectory's velocity plus a position correction (v = q̇_ref + Kp (q_ref − q); the drive's PI velocity loop
// then integrates the remaining error away, so gravity leaves no steady offset). The fingers: position mode to
// the pre-shape, then velocity mode closing with the drive's current limit (the grip force) until they stop on
// the object; the contact force between hand and object is measured from the simulation's contacts (the
// tactile pads' among them).
#include <algorithm>
#include <cmath>

#include "core/error.h"
#include "core/format.h"
#include "physics/builtin_drives.h"
#include "physics/simulation.h"
#include "pickplace/internal.h"

namespace graspsim::pickplace {
namespace {

constexpr double kTrackGain = 20;        // 1/s: the position correction on top of the trajectory's velocity
constexpr double kSettle = 0.25;         // s held at the end of each motion
constexpr double kSlip = 0.01;           // m: the object moved this far in the hand: it slipped
constexpr double kProgressPeriod = 0.05; // s of simulated time between progress calls

// A drive for an arm joint: a DC motor whose current limit gives the joint's rated effort (the URDF's, else
// 150 N m). k_t and the ratio are a generic servo's; the gains make a stiff velocity loop (overdamped with the
// back-EMF) — an assumed drive, not the arm maker's.
DcMotorParams ArmDrive(const JointSpec& joint) {
  DcMotorParams p;
  p.resistance = 1.0;
  p.ratio = 100;
  p.current_limit = 20;
  const double effort = joint.effort_limit > 0 ? joint.effort_limit : 150;
  p.torque_constant = effort / (p.ratio * p.current_limit);
  const double speed = joint.velocity_limit > 0 ? joint.velocity_limit : 3;
  p.voltage_limit = 1.5 * (p.resistance * p.current_limit + p.torque_constant * p.ratio * speed);
  // One volt gives ratio k_t / R of torque; make 1 mrad/s of error worth about 1 % of the rated effort.
  p.velocity_gain = 0.01 * effort / (p.ratio * p.torque_constant / p.resistance) / 1e-3;
  p.velocity_integral_gain = 10 * p.velocity_gain;
  p.position_gain = kTrackGain;
  p.max_velocity = speed;
  return p;
}

class Runner {
 public:
  Runner(const Setup& setup, const GraspPlan& plan, const Progress& progress, double f0, double f1,
         PickPlaceResult* result)
      : setup_(setup), plan_(plan), progress_(progress), f0_(f0), f1_(f1), result_(result),
        simulation_(setup.model), state_(setup.state) {
    simulation_.PrepareState(&state_);
    const SceneModel& model = *setup.model;
    arm_ = plan.open_arm->joint_indices();
    for (const size_t j : arm_) {
      JointActuator a;
      a.motor = ArmDrive(model.joints[j]);
      a.command = {ActuatorMode::kVelocity, 0, -1};
      state_.actuators[j] = a;
    }
    const RobotSpec& robot = model.robots[setup.robot];
    for (const auto& [j, q] : plan.open) {
      JointActuator a;
      a.motor = BuiltinDrive(robot, model.joints[j]);
      a.command = {ActuatorMode::kPosition, q, -1};
      state_.actuators[j] = a;
    }
    hold_ = Arm();
    in_hand_ = plan.object_in_hand;
  }

  VecX Arm() const {
    VecX q(arm_.size());
    for (size_t i = 0; i < arm_.size(); ++i) q[i] = state_.joint_positions[arm_[i]];
    return q;
  }

  // Steps `seconds` with the arm following `reference` (t → q, q̇); false when cancelled.
  template <typename Reference>
  bool Run(Stage stage, double seconds, const Reference& reference) {
    const double dt = setup_.model->simulation.time_step;
    const auto steps = static_cast<uint64_t>(std::ceil(seconds / dt));
    VecX q_ref, v_ref;
    for (uint64_t s = 0; s < steps; ++s) {
      reference(s * dt, &q_ref, &v_ref);
      for (size_t i = 0; i < arm_.size(); ++i) {
        const double q = state_.joint_positions[arm_[i]];
        state_.actuators[arm_[i]].command.value = v_ref[i] + kTrackGain * (q_ref[i] - q);
      }
      simulation_.Step(&state_, 1);
      elapsed_ += dt;
      if (elapsed_ >= next_progress_) {
        next_progress_ = elapsed_ + kProgressPeriod;
        const double f = f0_ + (f1_ - f0_) * std::min(1.0, elapsed_ / expected_);
        if (progress_ && !progress_(stage, f, *result_)) return false;
      }
    }
    return true;
  }
  bool Hold(Stage stage, double seconds) {
    const VecX zero = VecX::Zero(arm_.size());
    return Run(stage, seconds, [&](double, VecX* q, VecX* v) { *q = hold_, *v = zero; });
  }
  bool Follow(Stage stage, const motion::Trajectory& t) {
    if (!Run(stage, t.duration() + kSettle, [&](double time, VecX* q, VecX* v) {
          *q = t.Position(time), *v = time > t.duration() ? VecX::Zero(arm_.size()) : t.Velocity(time);
        })) {
      return false;
    }
    hold_ = t.waypoints().back();
    return true;
  }

  // Fingers: velocity mode toward the grasp's closed positions at the drive's own current limit.
  void StartClosing() {
    for (const auto& [j, q_open] : plan_.open) {
      const auto closed = std::find_if(plan_.closed.begin(), plan_.closed.end(),
                                       [j = j](const auto& c) { return c.first == j; });
      if (closed == plan_.closed.end()) continue;
      const double travel = closed->second - q_open;
      if (std::abs(travel) < 1e-6) continue;  // a joint the grasp does not move (the Barrett's spread): held
      const double direction = travel > 0 ? 1 : -1;
      const double speed = setup_.model->joints[j].type == JointType::kPrismatic ? 0.03 : 0.6;
      state_.actuators[j].command = {ActuatorMode::kVelocity, direction * speed, -1};
    }
  }
  void Open() {
    for (const auto& [j, q] : plan_.open) state_.actuators[j].command = {ActuatorMode::kPosition, q, -1};
  }
  bool FingersStopped() const {
    for (const auto& [j, q] : plan_.open) {
      if (std::abs(state_.joint_velocities[j]) > 2e-3) return false;
    }
    return true;
  }

  // The hand's contact force on the object, N (sum of magnitudes over the contact points and pad elements).
  double GripForce() const {
    const auto& contacts = simulation_.contacts();
    const auto& forces = simulation_.contact_forces();
    const std::string prefix = setup_.arm_id + "/";
    double sum = 0;
    for (size_t i = 0; i < contacts.size(); ++i) {
      const uint32_t a = contacts[i].body_a, b = contacts[i].body_b;
      const uint32_t other = a == setup_.object ? b : (b == setup_.object ? a : UINT32_MAX);
      if (other == UINT32_MAX || setup_.model->bodies[other].robot_id != setup_.arm_id) continue;
      sum += forces[i].norm();
    }
    return sum;
  }

  // How far the object moved in the hand since the grasp, m.
  Pose Hand() const { return state_.body_poses[setup_.model->body_index.at(setup_.tip)]; }
  double Slip() const { return ((Hand() * in_hand_).position - state_.body_poses[setup_.object].position).norm(); }

  const Setup& setup_;
  const GraspPlan& plan_;
  const Progress& progress_;
  double f0_, f1_;
  PickPlaceResult* result_;
  Simulation simulation_;
  SceneState state_;
  std::vector<size_t> arm_;
  VecX hold_;
  Pose in_hand_;  // the object in the hand frame: planned, then as measured after the lift
  double elapsed_ = 0, next_progress_ = 0, expected_ = 10;
};

}  // namespace

std::string Execute(const Setup& setup, const GraspPlan& plan, const std::vector<ArmMotion>& planned,
                    const Replan& replan, const Progress& progress, double f0, double f1, PickPlaceResult* result) {
  Runner r(setup, plan, progress, f0, f1, result);
  r.expected_ = 2.5;
  for (const ArmMotion& m : planned) r.expected_ += m.trajectory.duration() + kSettle;
  std::vector<ArmMotion>& motions = result->motions;
  motions = planned;
  const auto done = [&] { result->simulated_seconds += r.elapsed_; };
  bool closed = false;
  if (!r.Hold(Stage::kApproach, 0.3)) return done(), "cancelled";  // the fingers open to the pre-shape
  for (size_t i = 0; i < motions.size(); ++i) {
    const ArmMotion m = motions[i];
    if (m.closed && !closed) {
      r.StartClosing();
      double t = 0;
      while (t < 2.0) {
        if (!r.Hold(Stage::kClose, 0.05)) return done(), "cancelled";
        t += 0.05;
        if (t >= 0.3 && r.FingersStopped()) break;
      }
      if (!r.Hold(Stage::kClose, 0.2)) return done(), "cancelled";
      result->grip_force = r.GripForce();
      if (result->grip_force < 0.5) return done(), "missed: the fingers closed on nothing (contact force " +
                                                  FormatNumber(result->grip_force) + " N)";
      closed = true;
      // Where the grip really holds the object: a parallel gripper centres it between its jaws, so it sits up to
      // a centimetre or two from the planned grasp (the planner closes each jaw on its own). From here on a slip is
      // a motion relative to this grip.
      r.in_hand_ = r.Hand().Inverse() * r.state_.body_poses[setup.object];
    } else if (!m.closed && closed) {
      const double slip = r.Slip();
      if (slip > kSlip) return done(), "slipped during the transfer: the object moved " + FormatNumber(std::round(slip * 1e4) / 10) +
                                           " mm in the hand";
      r.Open();
      if (!r.Hold(Stage::kRelease, 0.5)) return done(), "cancelled";
      closed = false;
    }
    if (!r.Follow(m.stage, m.trajectory)) return done(), "cancelled";
    if (closed && m.stage == Stage::kLift) {
      // The place is planned again for the measured grip (what the tactile pads and the jaw positions tell a
      // real controller), from where the arm is now.
      const double slip = r.Slip();
      if (slip > kSlip) return done(), "slipped during the lift: the object moved " + FormatNumber(std::round(slip * 1e4) / 10) +
                                           " mm in the hand";
      r.in_hand_ = r.Hand().Inverse() * r.state_.body_poses[setup.object];
      std::vector<ArmMotion> rest;
      const std::string failure = replan(r.in_hand_, r.hold_, &rest);
      if (!failure.empty()) return done(), failure;
      motions.resize(i + 1);
      motions.insert(motions.end(), rest.begin(), rest.end());
    }
  }
  if (!r.Hold(Stage::kRetreat, 0.3)) return done(), "cancelled";
  done();
  // Leave the arm holding where it ended (position mode), so stepping the scene later keeps it up.
  for (const size_t j : r.arm_) r.state_.actuators[j].command = {ActuatorMode::kPosition, r.state_.joint_positions[j], -1};
  const Pose object = r.state_.body_poses[setup.object];
  result->object_pose = object;
  result->position_error = (object.position - setup.goal.position).norm();
  result->orientation_error = object.orientation.angularDistance(setup.goal.orientation);
  result->final_state = r.state_;
  if (result->position_error > setup.options.position_tolerance ||
      result->orientation_error > setup.options.orientation_tolerance) {
    return "missed the goal: the object ended " + FormatNumber(std::round(result->position_error * 1e4) / 10) + " mm and " +
           FormatNumber(std::round(result->orientation_error * 1800 / M_PI) / 10) + "° from it";
  }
  return "";
}

}  // namespace graspsim::pickplace
