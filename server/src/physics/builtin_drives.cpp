#include "physics/builtin_drives.h"

#include <numbers>

#include "physics/actuators.h"

namespace graspsim {

DcMotorParams ZAxisDriveParams() {
  // A ball screw of 10 mm lead (ratio 2π/0.01 ≈ 628 rad/m) on a small 48 V servo motor: k_t 0.05 N m/A, R 1 Ω,
  // η 0.9, 10 A: 283 N at the limit, above the 26 N the carriage, gripper and a 0.2 kg object weigh and below
  // the axis's 500 N rating; no-load speed 48 V / (k_e · ratio) ≈ 1.5 m/s, so the voltage never limits 0.2 m/s.
  DcMotorParams p;
  p.resistance = 1.0;
  p.inductance = 0;  // L/R of such a motor is ~0.1 ms, far below the 1 ms step
  p.torque_constant = 0.05;
  p.efficiency = 0.9;
  p.ratio = 2 * std::numbers::pi / 0.010;
  p.current_limit = 10;
  p.voltage_limit = 48;
  // Gains for ~2.6 kg on the axis. One volt gives b = ratio η k_t / R ≈ 28 N; the back-EMF damps with
  // B = ratio² η k_t² / R ≈ 890 N s/m. Kv = 200 V/(m/s) adds b Kv ≈ 5.7 kN s/m: a velocity loop of ~2500 rad/s,
  // far above the position loop. Ki = 4000 V/m removes a load's velocity error in (B + b Kv)/(b Ki) ≈ 60 ms.
  // Kp = 200 1/s: a set-point moving at v is tracked with a lag of v/Kp (0.5 mm at 0.1 m/s, 1 mm at 0.2 m/s);
  // the weight alone leaves 26 N / (B + b Kv) / Kp ≈ 0.02 mm before the integral removes it. The position
  // loop's stiffness b Kv Kp ≈ 1.1 MN/m with 6.5 kN s/m of damping is overdamped (ζ ≈ 1.9) on 2.6 kg.
  p.velocity_gain = 200;
  p.velocity_integral_gain = 4000;
  p.position_gain = 200;
  p.max_velocity = 0.25;  // m/s: headroom above the axis's 0.2 m/s so the position loop never saturates
  return p;
}

DcMotorParams BuiltinDrive(const RobotSpec& robot, const JointSpec& joint) {
  // The PG70 alone, on the z axis, or on an arm's flange ("builtin:<arm>_pg70").
  const bool pg70 = robot.source.ends_with("pg70") || robot.source == "builtin:schunk_pg70_on_z_axis";
  if (robot.source == "builtin:schunk_pg70_on_z_axis" && joint.id == robot.id + "/z_axis") return ZAxisDriveParams();
  if (pg70 && joint.type == JointType::kPrismatic) return Pg70DriveParams();
  return DcMotorParams();
}

}  // namespace graspsim
