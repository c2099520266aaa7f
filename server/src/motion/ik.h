// Inverse kinematics of an ArmModel's tip: every solution where the arm allows a closed form, damped least
// squares otherwise. Solutions are exact to the round-off of double arithmetic: FK of each reproduces the
// target to better than 1e-9 m and rad (tests/cpp/motion/ik_test.cpp), and lies within the joint limits.
//
// Closed form (SphericalWristIk): six revolute joints with the ortho-parallel layout of industrial arms (KUKA's
// KR series): axes z, y, y, x, y, x with joint origins offset only in the x-z plane of the arm, A4, A5 and A6
// meeting in one point (the wrist centre). The wrist centre fixes A1 (two ways: facing it or reaching over
// backwards), A3 (elbow up or down) and A2; the wrist's X-Y-X Euler angles give A4 to A6 (two ways: flipped or
// not). Up to 8 solutions, plus the 2π copies of A1, A4, A6 that the ranges allow (A6 of the KR 5 turns ±358°).
//
// Damped least squares (any arm, the PA10's 7 joints): q += Jᵀ (J Jᵀ + λ² I)⁻¹ e, e the 6-vector of position
// error and rotation-vector error, λ shrinking with the error (Nakamura & Hanafusa 1986 / Wampler 1986 damping),
// joints clamped to their limits after each step; restarts from seeded random configurations collect distinct
// solutions. A redundant arm has infinitely many; this returns up to `max_solutions` of them.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "motion/arm.h"

namespace graspsim::motion {

struct IkOptions {
  size_t max_solutions = 8;        // DLS only: the closed form returns every solution
  uint64_t seed = 1;
  unsigned restarts = 32;          // DLS: random starts tried (after the seed configuration)
  unsigned iterations = 200;       // DLS: steps per start
  double tolerance = 1e-12;        // DLS: converged when |position error| + |rotation error| is below (m, rad)
  std::optional<VecX> near;        // DLS: start here first; solutions are sorted by distance to it (both methods)
};

struct IkResult {
  std::vector<VecX> solutions;     // within the joint limits, distinct (> 1e-6 rad apart)
  std::string failure;             // why there is none: out of reach, outside the limits, no convergence
  bool analytic = false;           // the closed form answered
};

// The tip's world pose `target` (tip as in ArmModel::tip_body()).
IkResult SolveIk(const ArmModel& arm, const Pose& target, const IkOptions& options = {});

// The closed-form solver for arms of the layout above; nullopt when the arm is not of it.
class SphericalWristIk {
 public:
  static std::optional<SphericalWristIk> Detect(const ArmModel& arm);
  // All solutions within the limits; *failure says why there are none.
  std::vector<VecX> Solve(const ArmModel& arm, const Pose& target, std::string* failure) const;

 private:
  double h_ = 0, a1_ = 0, l2_ = 0, a2_ = 0, l3_ = 0, d6_ = 0;  // m (see the .cpp)
};

// Damped least squares from several starts.
IkResult SolveIkDls(const ArmModel& arm, const Pose& target, const IkOptions& options);

}  // namespace graspsim::motion
