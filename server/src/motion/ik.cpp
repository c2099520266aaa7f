#include "motion/ik.h"

#include <algorithm>
#include <cmath>
#include <random>

#include <Eigen/Cholesky>

#include "motion/short_number.h"

namespace graspsim::motion {
namespace {

// The 6-vector that moves `from` toward `to`: position difference and the rotation vector of to·fromᵀ.
Vec6 PoseError(const Rigid& to, const Rigid& from) {
  const Eigen::AngleAxisd rotation(to.rotation * from.rotation.transpose());
  return Stack(to.translation - from.translation, rotation.angle() * rotation.axis());
}

double ErrorNorm(const Vec6& e) { return e.head<3>().norm() + e.tail<3>().norm(); }

void SortByDistance(const std::optional<VecX>& near, std::vector<VecX>* solutions) {
  if (!near) return;
  std::stable_sort(solutions->begin(), solutions->end(), [&](const VecX& a, const VecX& b) {
    return (a - *near).squaredNorm() < (b - *near).squaredNorm();
  });
}

bool IsNew(const std::vector<VecX>& found, const VecX& q) {
  return std::none_of(found.begin(), found.end(), [&](const VecX& f) { return (f - q).norm() < 1e-6; });
}

}  // namespace

IkResult SolveIkDls(const ArmModel& arm, const Pose& target, const IkOptions& options) {
  const Rigid goal = Rigid::From(target);
  const size_t n = arm.dof();
  std::mt19937_64 rng(options.seed);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  IkResult result;
  double best_error = INFINITY;
  const unsigned starts = options.restarts + (options.near ? 1 : 0);
  for (unsigned start = 0; start < starts && result.solutions.size() < options.max_solutions; ++start) {
    VecX q(n);
    if (start == 0 && options.near && options.near->size() == static_cast<long>(n)) {
      q = options.near->cwiseMax(arm.lower()).cwiseMin(arm.upper());
    } else {
      for (size_t i = 0; i < n; ++i) q[i] = arm.lower()[i] + unit(rng) * (arm.upper()[i] - arm.lower()[i]);
    }
    double error = INFINITY, checkpoint = INFINITY;
    for (unsigned it = 0; it < options.iterations; ++it) {
      const Vec6 e = PoseError(goal, arm.TipTransform(q));
      error = ErrorNorm(e);
      if (error < options.tolerance) break;
      if (it % 16 == 0) {  // stuck (against a limit, in a local minimum): another start is cheaper
        if (error > 0.5 * checkpoint) break;
        checkpoint = error;
      }
      const Eigen::Matrix<double, 6, Eigen::Dynamic> j = arm.Jacobian(q);
      // Damping fades with the error: robust far away, Gauss-Newton's fast convergence close by.
      const double lambda2 = std::min(1e-2, 1e-2 * error * error);
      const Eigen::Matrix<double, 6, 6> a = j * j.transpose() + lambda2 * Eigen::Matrix<double, 6, 6>::Identity();
      VecX step = j.transpose() * a.ldlt().solve(e);
      const double largest = step.cwiseAbs().maxCoeff();
      if (largest > 0.5) step *= 0.5 / largest;  // no jumps across the workspace on one linearisation
      q = (q + step).cwiseMax(arm.lower()).cwiseMin(arm.upper());
    }
    best_error = std::min(best_error, error);
    if (error < options.tolerance && IsNew(result.solutions, q)) result.solutions.push_back(q);
  }
  if (result.solutions.empty()) {
    result.failure = "no solution within the joint limits from " + std::to_string(starts) +
                     " starts of damped least squares (smallest remaining error " + Short(best_error) +
                     " m + rad): the target is out of reach or outside the limits";
  }
  SortByDistance(options.near, &result.solutions);
  return result;
}

IkResult SolveIk(const ArmModel& arm, const Pose& target, const IkOptions& options) {
  const std::optional<SphericalWristIk> closed_form = SphericalWristIk::Detect(arm);
  if (!closed_form) return SolveIkDls(arm, target, options);
  IkResult result;
  result.analytic = true;
  result.solutions = closed_form->Solve(arm, target, &result.failure);
  SortByDistance(options.near, &result.solutions);
  return result;
}

}  // namespace graspsim::motion
