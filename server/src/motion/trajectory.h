// Time parameterisation of a joint-space path under per-joint velocity and acceleration limits.
//
// Rest to rest per segment: the arm stops at every waypoint (the path's corners), and between two waypoints all
// joints follow one trapezoidal profile s(t) ∈ [0, 1] scaled by their displacement Δ_i, so they start and arrive
// together along the straight segment the collision checker verified. The profile's peak speed V and
// acceleration A are the largest that every joint allows: V = min_i v_i / |Δ_i|, A = min_i a_i / |Δ_i|;
// a segment takes 1/V + V/A when it reaches V (V² < A), else the triangle 2/√A. Shortcutting leaves few corners,
// so the stops cost little; no joint ever exceeds its limits, and the arm never leaves the checked segments.
#pragma once

#include <vector>

#include "motion/arm.h"

namespace graspsim::motion {

class Trajectory {
 public:
  Trajectory() = default;
  // `velocity` and `acceleration` per joint, > 0 (rad/s, rad/s² or m/s, m/s²).
  Trajectory(std::vector<VecX> waypoints, const VecX& velocity, const VecX& acceleration);

  const std::vector<VecX>& waypoints() const { return waypoints_; }
  const std::vector<double>& times() const { return times_; }  // arrival at each waypoint, s; times()[0] = 0
  double duration() const { return times_.empty() ? 0 : times_.back(); }
  // Position, velocity and acceleration at time t (clamped to [0, duration]).
  VecX Position(double t) const;
  VecX Velocity(double t) const;
  VecX Acceleration(double t) const;

 private:
  struct Segment {
    double v = 0, a = 0;        // the normalised profile's peak speed and acceleration, 1/s and 1/s²
    double ramp = 0, cruise = 0;  // durations of each ramp and of the cruise, s
  };
  // s, ṡ, s̈ of segment k at local time τ.
  void Profile(size_t k, double tau, double* s, double* sd, double* sdd) const;
  size_t SegmentAt(double t, double* tau) const;

  std::vector<VecX> waypoints_;
  std::vector<double> times_;
  std::vector<Segment> segments_;
};

}  // namespace graspsim::motion
