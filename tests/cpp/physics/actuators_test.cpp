// The DC motor drive against the motor equations: no-load speed, stall force, the current limit as a force limit,
// the inductive current rise, the velocity and position loops on an inertia the test integrates itself, and the
// PG70 drive's datasheet figures.
#include "physics/actuators.h"

#include <cmath>

#include <gtest/gtest.h>

namespace graspsim {
namespace {

DcMotorParams Motor() {
  DcMotorParams p;  // R 1 Ω, k_t 0.05 N m/A, ratio 100, 5 A, 24 V and the default loop gains
  p.efficiency = 0.9;
  return p;
}

ActuatorCommand Command(ActuatorMode mode, double value, double current_limit = -1) {
  ActuatorCommand c;
  c.mode = mode;
  c.value = value;
  c.current_limit = current_limit;
  return c;
}

double ForcePerAmp(const DcMotorParams& p) { return p.ratio * p.efficiency * p.torque_constant; }

// A joint with only inertia, driven by the motor: symplectic Euler with the force of the step's start state.
struct Joint {
  double q = 0, q_dot = 0;
  DcMotorState motor;
  ActuatorOutput last;
  double fastest = 0;  // max |q̇| seen

  void Run(const DcMotorParams& p, const ActuatorCommand& command, double inertia, double dt, double seconds) {
    const long steps = std::lround(seconds / dt);
    for (long i = 0; i < steps; ++i) {
      last = StepDcMotor(p, command, q, q_dot, dt, &motor);
      q_dot += dt * last.joint_force / inertia;
      q += dt * q_dot;
      fastest = std::max(fastest, std::abs(q_dot));
    }
  }
};

TEST(ActuatorTest, VoltageModeReachesTheNoLoadSpeed) {
  const DcMotorParams p = Motor();
  for (double volts : {12.0, -6.0, 24.0}) {
    Joint joint;
    joint.Run(p, Command(ActuatorMode::kVoltage, volts), 0.5, 1e-3, 5);
    const double no_load = volts / (p.torque_constant * p.ratio);  // back-EMF k_e ratio q̇ balances V
    EXPECT_NEAR(joint.q_dot / no_load, 1, 1e-9) << volts << " V";
    EXPECT_NEAR(joint.last.current, 0, 1e-9);
  }
}

TEST(ActuatorTest, StallForceIsVoltageOverResistanceUpToTheCurrentLimit) {
  const DcMotorParams p = Motor();
  DcMotorState state;
  for (double volts : {2.0, -3.0}) {  // below the limit: i = V / R
    const ActuatorOutput out = StepDcMotor(p, Command(ActuatorMode::kVoltage, volts), 0, 0, 1e-3, &state);
    EXPECT_NEAR(out.joint_force, p.ratio * p.efficiency * p.torque_constant * volts / p.resistance, 1e-12);
    EXPECT_DOUBLE_EQ(out.voltage, volts);
  }
  // 24 V into 1 Ω would be 24 A: the drive holds 5 A, i.e. 22.5 N m; a command above 24 V is clamped.
  for (double volts : {24.0, 1000.0, -1000.0}) {
    const ActuatorOutput out = StepDcMotor(p, Command(ActuatorMode::kVoltage, volts), 0, 0, 1e-3, &state);
    EXPECT_DOUBLE_EQ(out.joint_force, std::copysign(ForcePerAmp(p) * p.current_limit, volts));
    EXPECT_DOUBLE_EQ(out.current, std::copysign(p.current_limit, volts));
    EXPECT_LE(std::abs(out.voltage), p.voltage_limit);
  }
}

TEST(ActuatorTest, CurrentLimitCapsTheForceExactly) {
  // The PG70 force-control principle: with the finger blocked the force is ratio η k_t i_max, whatever the loop
  // asks for. A command may lower the drive's limit, never raise it.
  const DcMotorParams p = Motor();
  for (double limit : {0.0, 0.7, 1.5, 5.0, 50.0}) {
    DcMotorState state;
    ActuatorOutput out;
    for (int i = 0; i < 1000; ++i) out = StepDcMotor(p, Command(ActuatorMode::kVelocity, 2, limit), 0, 0, 1e-3, &state);
    EXPECT_EQ(out.joint_force, ForcePerAmp(p) * std::min(limit, p.current_limit)) << limit << " A";
  }
}

TEST(ActuatorTest, InductiveCurrentRisesExponentially) {
  DcMotorParams p = Motor();
  p.inductance = 5e-3;  // L / R = 5 ms
  const double volts = 3;
  for (double dt : {1e-4, 7e-4, 3e-3}) {
    DcMotorState state;
    for (int n = 1; n <= 40; ++n) {
      const ActuatorOutput out = StepDcMotor(p, Command(ActuatorMode::kVoltage, volts), 0, 0, dt, &state);
      const double expected = volts / p.resistance * (1 - std::exp(-n * dt * p.resistance / p.inductance));
      ASSERT_NEAR(out.current, expected, 1e-9) << "dt " << dt << " step " << n;
      ASSERT_NEAR(out.joint_force, ForcePerAmp(p) * expected, 1e-9 * ForcePerAmp(p));
    }
  }
  // Exact for any step: one 1 s step lands on V / R (explicit Euler would need dt < 2 L / R = 10 ms).
  DcMotorState state;
  EXPECT_NEAR(StepDcMotor(p, Command(ActuatorMode::kVoltage, volts), 0, 0, 1.0, &state).current, 3, 1e-12);
}

TEST(ActuatorTest, VelocityModeTracksTheSetPoint) {
  const DcMotorParams p = Motor();
  for (double target : {2.0, -1.0}) {
    Joint joint;
    joint.Run(p, Command(ActuatorMode::kVelocity, target), 1.0, 1e-3, 0.5);
    for (int i = 0; i < 50; ++i) {  // and stays there
      joint.Run(p, Command(ActuatorMode::kVelocity, target), 1.0, 1e-3, 0.01);
      ASSERT_NEAR(joint.q_dot / target, 1, 0.01) << "t = " << 0.5 + 0.01 * i;
    }
  }
}

TEST(ActuatorTest, PositionModeReachesTheTargetAtBoundedSpeed) {
  const DcMotorParams p = Motor();
  Joint joint;
  joint.Run(p, Command(ActuatorMode::kPosition, 1.0), 1.0, 1e-3, 4);
  EXPECT_NEAR(joint.q, 1.0, 1e-4);
  EXPECT_NEAR(joint.q_dot, 0, 1e-3);
  EXPECT_LT(joint.fastest, 1.05 * p.max_velocity) << "the set-point is capped at max_velocity";
}

TEST(ActuatorTest, OffModeExertsNothingAndResetsTheDrive) {
  const DcMotorParams p = Motor();
  DcMotorState state{3.0, 0.2};
  const ActuatorOutput out = StepDcMotor(p, Command(ActuatorMode::kOff, 12), 0.1, 2.0, 1e-3, &state);
  EXPECT_EQ(out.joint_force, 0);
  EXPECT_EQ(out.current, 0);
  EXPECT_EQ(state.current, 0);
  EXPECT_EQ(state.velocity_error_integral, 0);
}

TEST(ActuatorTest, Pg70GivesTwoHundredNewtonsAtTheRatedCurrentAndItsTopSpeed) {
  const DcMotorParams p = Pg70DriveParams();
  EXPECT_NEAR(ForcePerAmp(p) * p.current_limit, 200, 200 * 1e-9);
  EXPECT_GE(p.voltage_limit / (p.torque_constant * p.ratio), 0.082) << "no-load speed at 24 V, m/s";
  EXPECT_DOUBLE_EQ(p.voltage_limit, 24);
  // Stalled at full voltage, the current limit sets the force: 200 N.
  DcMotorState state;
  EXPECT_NEAR(StepDcMotor(p, Command(ActuatorMode::kVoltage, 24), 0, 0, 1e-3, &state).joint_force, 200, 1e-9);
}

TEST(ActuatorTest, Pg70FingerClosesAtTopSpeedThenPressesWithTheSetCurrent) {
  // A 0.1 kg finger (dt 10 µs: the drive's back-EMF damping, ~2 kN s/m, is stiff for so light a body).
  const DcMotorParams p = Pg70DriveParams();
  Joint finger;
  const ActuatorCommand close = Command(ActuatorMode::kVelocity, 0.082, 2.0);
  finger.Run(p, close, 0.1, 1e-5, 0.5);
  EXPECT_NEAR(finger.q_dot / 0.082, 1, 0.01);
  // Blocked by an object for 1 s: the force is ratio η k_t · 2 A, and the integral holds while the current
  // limit does (anti-windup) instead of growing by 0.082 m/s × 1 s, 82 V worth of surge at release.
  DcMotorState& motor = finger.motor;
  const double integral = motor.velocity_error_integral;
  ActuatorOutput out;
  for (int i = 0; i < 100000; ++i) {
    out = StepDcMotor(p, close, finger.q, 0, 1e-5, &motor);
    ASSERT_NEAR(out.joint_force, ForcePerAmp(p) * 2.0, 1e-9) << "step " << i;
  }
  EXPECT_NEAR(motor.velocity_error_integral, integral, 0.082 * 1e-5);
  // Released, the finger returns to the set speed without a wound-up surge.
  finger.q_dot = 0;
  finger.fastest = 0;
  finger.Run(p, close, 0.1, 1e-5, 0.5);
  EXPECT_LT(finger.fastest, 1.1 * 0.082);
  EXPECT_NEAR(finger.q_dot / 0.082, 1, 0.01);
}

TEST(ActuatorTest, Pg70PositionModeReachesTheTarget) {
  const DcMotorParams p = Pg70DriveParams();
  Joint finger;
  finger.q = 0.03;
  finger.Run(p, Command(ActuatorMode::kPosition, 0.01), 0.1, 1e-5, 1);
  EXPECT_NEAR(finger.q, 0.01, 1e-4);
  EXPECT_LT(finger.fastest, 1.05 * 0.082);
}

TEST(ActuatorTest, LinearisationMatchesFiniteDifferences) {
  // The implicit solve uses ∂F/∂q̇ and ∂F/∂q: they must be the slopes of the force the step returns (central
  // differences from the same motor state; the law is piecewise linear, so they agree to rounding), and 0 where
  // the current limit holds the force constant.
  DcMotorParams inductive = Motor();
  inductive.inductance = 2e-3;
  struct Case {
    DcMotorParams motor;
    ActuatorCommand command;
    double q, q_dot;
  };
  const Case cases[] = {{Motor(), Command(ActuatorMode::kVoltage, 3), 0, 0.2},
                        {Motor(), Command(ActuatorMode::kVelocity, 0.3), 0, 0.25},
                        {Motor(), Command(ActuatorMode::kPosition, 0.01), 0, 0.18},
                        {inductive, Command(ActuatorMode::kVelocity, 0.3), 0, 0.25},
                        {Pg70DriveParams(), Command(ActuatorMode::kVelocity, -0.05, 2.0), 0.02, -0.0499}};
  const double dt = 1e-3, eps = 1e-7;
  for (const Case& c : cases) {
    DcMotorState state;
    state.current = 0.5;
    state.velocity_error_integral = 1e-4;
    auto force = [&](double q, double q_dot) {
      DcMotorState copy = state;
      return StepDcMotor(c.motor, c.command, q, q_dot, dt, &copy).joint_force;
    };
    DcMotorState copy = state;
    const ActuatorOutput out = StepDcMotor(c.motor, c.command, c.q, c.q_dot, dt, &copy);
    ASSERT_LT(std::abs(out.current), c.motor.current_limit) << "the case must be unsaturated";
    const double damping = (force(c.q, c.q_dot + eps) - force(c.q, c.q_dot - eps)) / (2 * eps);
    const double stiffness = (force(c.q + eps, c.q_dot) - force(c.q - eps, c.q_dot)) / (2 * eps);
    EXPECT_NEAR(out.damping / damping, 1, 1e-6) << static_cast<int>(c.command.mode);
    EXPECT_LT(out.damping, 0);
    if (c.command.mode == ActuatorMode::kPosition) {
      EXPECT_NEAR(out.stiffness / stiffness, 1, 1e-6);
      EXPECT_LT(out.stiffness, 0);
    } else {
      EXPECT_EQ(out.stiffness, 0);
      EXPECT_NEAR(stiffness, 0, 1e-6);
    }
  }
  // Stalled against an object at the current limit: the force is constant.
  DcMotorState stalled;
  stalled.velocity_error_integral = -0.01;  // wound up while the finger was blocked
  const ActuatorOutput held =
      StepDcMotor(Pg70DriveParams(), Command(ActuatorMode::kVelocity, -0.05, 2.0), 0.02, 0, dt, &stalled);
  EXPECT_NEAR(std::abs(held.current), 2.0, 1e-12);
  EXPECT_EQ(held.damping, 0);
  EXPECT_EQ(held.stiffness, 0);
}

}  // namespace
}  // namespace graspsim
