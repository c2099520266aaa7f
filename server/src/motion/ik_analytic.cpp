// The closed form of ik.h for ortho-parallel arms with a spherical wrist. In the frame of joint 1 (before its
// rotation) the chain is
//   Rz(q1) · T(a1, 0, h) · Ry(q2) · T(0, 0, l2) · Ry(q3) · T(x4, 0, a2) · Rx(q4) · T(x5, 0, 0) · Ry(q5)
//          · T(d6, 0, 0) · Rx(q6),            l3 = x4 + x5,
// so at q = 0 the upper arm (l2) stands along z, the forearm (l3, its axis a2 above A3) lies along x, and the
// wrist centre is where A4, A5 and A6 meet. In the arm's plane (after q1) the wrist centre c' = (x, z) from A2 is
//   c' = l2 (sin q2, cos q2) + L (cos(q2 + β), −sin(q2 + β)),   L = √(l3² + a2²), ψ = atan2(a2, l3), β = q3 − ψ,
// hence |c'|² = l2² + L² − 2 l2 L sin β fixes q3 (two ways) and then q2 by a planar rotation.
#include <algorithm>
#include <cmath>

#include "motion/ik.h"
#include "motion/short_number.h"

namespace graspsim::motion {
namespace {

bool IsAxis(const Vec3& a, const Vec3& b) { return (a - b).norm() < 1e-12; }
bool NoRotation(const Rigid& t) { return (t.rotation - Mat3::Identity()).norm() < 1e-12; }

double Wrap(double a) { return std::remainder(a, 2 * EIGEN_PI); }

// Every copy q + 2πk of the solution's angles that lies within the limits (the cartesian product per joint).
void AddCopiesWithinLimits(const ArmModel& arm, const VecX& q, std::vector<VecX>* out) {
  std::vector<std::vector<double>> options(q.size());
  for (long i = 0; i < q.size(); ++i) {
    const double base = Wrap(q[i]);
    for (int k = -2; k <= 2; ++k) {
      const double v = base + 2 * EIGEN_PI * k;
      if (v >= arm.lower()[i] && v <= arm.upper()[i]) options[i].push_back(v);
    }
    if (options[i].empty()) return;
  }
  std::vector<size_t> pick(q.size(), 0);
  while (true) {
    VecX v(q.size());
    for (long i = 0; i < q.size(); ++i) v[i] = options[i][pick[i]];
    out->push_back(v);
    long i = 0;
    while (i < q.size() && ++pick[i] == options[i].size()) pick[i++] = 0;
    if (i == q.size()) return;
  }
}

}  // namespace

std::optional<SphericalWristIk> SphericalWristIk::Detect(const ArmModel& arm) {
  if (arm.dof() != 6) return std::nullopt;
  for (JointType type : arm.dof_types()) {
    if (type != JointType::kRevolute && type != JointType::kContinuous) return std::nullopt;
  }
  const Vec3 x = Vec3::UnitX(), y = Vec3::UnitY(), z = Vec3::UnitZ();
  const Vec3 axes[6] = {z, y, y, x, y, x};
  for (int i = 0; i < 6; ++i) {
    if (!IsAxis(arm.dof_axes()[i], axes[i])) return std::nullopt;
    if (i > 0 && !NoRotation(arm.dof_offsets()[i])) return std::nullopt;
  }
  const auto& o = arm.dof_offsets();
  const Vec3 o1 = o[1].translation, o2 = o[2].translation, o3 = o[3].translation, o4 = o[4].translation,
             o5 = o[5].translation;
  const double eps = 1e-12;
  if (std::abs(o1.y()) > eps || std::abs(o2.x()) > eps || std::abs(o2.y()) > eps || std::abs(o3.y()) > eps ||
      o4.tail<2>().norm() > eps || o5.tail<2>().norm() > eps) {
    return std::nullopt;
  }
  SphericalWristIk ik;
  ik.a1_ = o1.x();
  ik.h_ = o1.z();
  ik.l2_ = o2.z();
  ik.a2_ = o3.z();
  ik.l3_ = o3.x() + o4.x();
  ik.d6_ = o5.x();
  if (ik.l2_ <= 0 || std::hypot(ik.l3_, ik.a2_) <= 0) return std::nullopt;
  return ik;
}

std::vector<VecX> SphericalWristIk::Solve(const ArmModel& arm, const Pose& target, std::string* failure) const {
  // The pose of link 6 in joint 1's frame.
  const Rigid j1 = arm.base() * arm.dof_offsets()[0];
  const Rigid local = j1.Inverse() * Rigid::From(target) * arm.tip_offset().Inverse();
  const Vec3 c = local.translation - d6_ * local.rotation.col(0);
  const double rho = std::hypot(c.x(), c.y());
  const double big_l = std::hypot(l3_, a2_), psi = std::atan2(a2_, l3_);

  std::vector<VecX> raw;
  double nearest_reach_miss = INFINITY;
  const double q1_front = rho > 1e-12 ? std::atan2(c.y(), c.x()) : 0.0;  // on the A1 axis: any q1 will do
  for (int back = 0; back < 2; ++back) {
    const double q1 = q1_front + (back ? EIGEN_PI : 0.0);
    const double x = (back ? -rho : rho) - a1_, z = c.z() - h_;
    const double d2 = x * x + z * z;
    double s = (d2 - l2_ * l2_ - big_l * big_l) / (2 * l2_ * big_l);  // = −sin β
    if (std::abs(s) > 1 + 1e-12) {
      const double miss = s > 0 ? std::sqrt(d2) - (l2_ + big_l) : std::abs(l2_ - big_l) - std::sqrt(d2);
      nearest_reach_miss = std::min(nearest_reach_miss, miss);
      continue;
    }
    s = std::clamp(s, -1.0, 1.0);
    for (int elbow = 0; elbow < 2; ++elbow) {
      const double beta = elbow ? -EIGEN_PI + std::asin(s) : -std::asin(s);
      const double q3 = beta + psi;
      const double k1 = l2_ - big_l * std::sin(beta), k2 = big_l * std::cos(beta);
      const double q2 = std::atan2(k1 * x - k2 * z, k2 * x + k1 * z);
      // Wrist: M = (Rz(q1) Ry(q2 + q3))ᵀ R6 = Rx(q4) Ry(q5) Rx(q6).
      const Mat3 r03 = (Eigen::AngleAxisd(q1, Vec3::UnitZ()) * Eigen::AngleAxisd(q2 + q3, Vec3::UnitY())).toRotationMatrix();
      const Mat3 m = r03.transpose() * local.rotation;
      const double s5 = std::hypot(m(1, 0), m(2, 0));
      if (s5 < 1e-9) {  // wrist singular: only q4 + q6 (q5 = 0) or q4 − q6 (q5 = π) is fixed; take q4 = 0
        const double q5 = m(0, 0) > 0 ? 0.0 : EIGEN_PI;
        const Mat3 rest = m * Eigen::AngleAxisd(-q5, Vec3::UnitY()).toRotationMatrix();
        const double sum = std::atan2(rest(2, 1), rest(1, 1));
        VecX q(6);
        q << q1, q2, q3, 0.0, q5, m(0, 0) > 0 ? sum : -sum;
        raw.push_back(q);
        continue;
      }
      const double q5 = std::atan2(s5, m(0, 0));
      const double q4 = std::atan2(m(1, 0), -m(2, 0)), q6 = std::atan2(m(0, 1), m(0, 2));
      VecX q(6);
      q << q1, q2, q3, q4, q5, q6;
      raw.push_back(q);
      q << q1, q2, q3, q4 + EIGEN_PI, -q5, q6 + EIGEN_PI;
      raw.push_back(q);
    }
  }
  if (raw.empty()) {
    *failure = "target out of reach: the wrist centre misses the arm's workspace by " + Short(nearest_reach_miss) +
               " m";
    return {};
  }
  std::vector<VecX> solutions;
  for (const VecX& q : raw) AddCopiesWithinLimits(arm, q, &solutions);
  if (solutions.empty()) {
    // Name the first joint that is out of range in the first raw solution.
    const VecX& q = raw.front();
    std::string detail;
    for (long i = 0; i < q.size() && detail.empty(); ++i) {
      const double v = Wrap(q[i]);
      if (v < arm.lower()[i] || v > arm.upper()[i]) {
        detail = arm.joint_ids()[i] + " = " + Short(v) + " rad, limits [" + Short(arm.lower()[i]) + ", " +
                 Short(arm.upper()[i]) + "]";
      }
    }
    *failure = "target outside the joint limits: all " + std::to_string(raw.size()) +
               " solutions violate them (the first: " + detail + ")";
  }
  return solutions;
}

}  // namespace graspsim::motion
