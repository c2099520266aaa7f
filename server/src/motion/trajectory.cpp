#include "motion/trajectory.h"

#include <algorithm>
#include <cmath>

namespace graspsim::motion {

Trajectory::Trajectory(std::vector<VecX> waypoints, const VecX& velocity, const VecX& acceleration)
    : waypoints_(std::move(waypoints)) {
  if (waypoints_.empty()) return;
  times_.push_back(0);
  for (size_t k = 0; k + 1 < waypoints_.size(); ++k) {
    const VecX delta = (waypoints_[k + 1] - waypoints_[k]).cwiseAbs();
    Segment segment;
    double v = INFINITY, a = INFINITY;
    for (long i = 0; i < delta.size(); ++i) {
      if (delta[i] <= 0) continue;
      v = std::min(v, velocity[i] / delta[i]);
      a = std::min(a, acceleration[i] / delta[i]);
    }
    if (std::isinf(v)) {  // no joint moves: a zero-length segment
      segments_.push_back(segment);
      times_.push_back(times_.back());
      continue;
    }
    if (v * v < a) {  // trapezoid: accelerate to V, cruise, brake
      segment.v = v;
      segment.a = a;
      segment.ramp = v / a;
      segment.cruise = 1 / v - v / a;
    } else {  // triangle: the peak speed √A is reached halfway
      segment.a = a;
      segment.v = std::sqrt(a);
      segment.ramp = 1 / std::sqrt(a);
    }
    segments_.push_back(segment);
    times_.push_back(times_.back() + 2 * segment.ramp + segment.cruise);
  }
}

void Trajectory::Profile(size_t k, double tau, double* s, double* sd, double* sdd) const {
  const Segment& g = segments_[k];
  const double total = 2 * g.ramp + g.cruise;
  if (total <= 0) {
    *s = 1, *sd = 0, *sdd = 0;
    return;
  }
  tau = std::clamp(tau, 0.0, total);
  const double s_ramp = 0.5 * g.a * g.ramp * g.ramp;
  if (tau < g.ramp) {
    *s = 0.5 * g.a * tau * tau, *sd = g.a * tau, *sdd = g.a;
  } else if (tau <= g.ramp + g.cruise) {
    *s = s_ramp + g.v * (tau - g.ramp), *sd = g.v, *sdd = 0;
  } else {
    const double left = total - tau;
    *s = 1 - 0.5 * g.a * left * left, *sd = g.a * left, *sdd = -g.a;
  }
}

size_t Trajectory::SegmentAt(double t, double* tau) const {
  const size_t k = std::upper_bound(times_.begin(), times_.end(), t) - times_.begin();
  const size_t segment = std::min(k == 0 ? 0 : k - 1, segments_.size() - 1);
  *tau = t - times_[segment];
  return segment;
}

VecX Trajectory::Position(double t) const {
  if (segments_.empty()) return waypoints_.empty() ? VecX() : waypoints_.front();
  double tau, s, sd, sdd;
  const size_t k = SegmentAt(t, &tau);
  Profile(k, tau, &s, &sd, &sdd);
  return waypoints_[k] + s * (waypoints_[k + 1] - waypoints_[k]);
}

VecX Trajectory::Velocity(double t) const {
  if (segments_.empty()) return VecX::Zero(waypoints_.empty() ? 0 : waypoints_.front().size());
  double tau, s, sd, sdd;
  const size_t k = SegmentAt(t, &tau);
  Profile(k, tau, &s, &sd, &sdd);
  return sd * (waypoints_[k + 1] - waypoints_[k]);
}

VecX Trajectory::Acceleration(double t) const {
  if (segments_.empty()) return VecX::Zero(waypoints_.empty() ? 0 : waypoints_.front().size());
  double tau, s, sd, sdd;
  const size_t k = SegmentAt(t, &tau);
  Profile(k, tau, &s, &sd, &sdd);
  return sdd * (waypoints_[k + 1] - waypoints_[k]);
}

}  // namespace graspsim::motion
