// The contact kernel's two builds against the scalar law (physics/contact_law.h) contact by contact: forces,
// normal forces, the pair sums rebuilt from each contact's ContactForce, and the bristle update (with the start's
// or the implicit step's end normal force) — over contacts that stick, slide, separate and sit at the static cap,
// with a shared normal and with mixed normals.
#include "physics/contact_kernel.h"

#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "physics/contact_law.h"

namespace graspsim {
namespace {

using contact_kernel::ContactRun;
using contact_kernel::RunSums;

struct Contacts {
  std::vector<double> px, py, pz, nx, ny, nz, depth, zx, zy, zz;
  std::vector<Vec3> point, normal, bristle;
};

// 37 contacts (not a multiple of any lane count): depths from separated to pressed, bristles from relaxed to
// beyond the cap, slip from sticking to sliding (by the twist).
Contacts MakeContacts(bool shared_normal) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> unit(-1, 1);
  Contacts c;
  for (int i = 0; i < 37; ++i) {
    const Vec3 p(0.05 * unit(rng), 0.05 * unit(rng), 0.5 + 0.05 * unit(rng));
    const Vec3 n = shared_normal || i % 3 ? Vec3(0.1, -0.2, 1).normalized()
                                          : Vec3(unit(rng), unit(rng), 1 + unit(rng)).normalized();
    const Vec3 z = (i % 5 == 0 ? 1e-3 : 1e-5) * Vec3(unit(rng), unit(rng), unit(rng));
    c.point.push_back(p), c.normal.push_back(n), c.bristle.push_back(z);
    c.px.push_back(p.x()), c.py.push_back(p.y()), c.pz.push_back(p.z());
    c.nx.push_back(n.x()), c.ny.push_back(n.y()), c.nz.push_back(n.z());
    c.depth.push_back(i % 7 == 0 ? -1e-4 : 1e-3 * (1 + unit(rng)));
    c.zx.push_back(z.x()), c.zy.push_back(z.y()), c.zz.push_back(z.z());
  }
  return c;
}

ContactRun RunOf(const Contacts& c, const double (&twist)[6]) {
  ContactRun run;
  run.count = c.px.size();
  run.px = c.px.data(), run.py = c.py.data(), run.pz = c.pz.data();
  run.nx = c.nx.data(), run.ny = c.ny.data(), run.nz = c.nz.data();
  run.depth = c.depth.data();
  run.zx = c.zx.data(), run.zy = c.zy.data(), run.zz = c.zz.data();
  for (int k = 0; k < 6; ++k) run.twist[k] = twist[k];
  run.law.stribeck_velocity = 1e-3;
  run.law.viscous_friction = 0.05;
  run.friction = run.law.HasFriction();
  run.h = 1e-3;
  return run;
}

using Mat6 = Eigen::Matrix<double, 6, 6>;
using RowMajor6 = Eigen::Matrix<double, 6, 6, Eigen::RowMajor>;

// Σ Eᵀ (h D + h² K) E from the kernel's sums, and from the scalar law's ContactForce directly.
Mat6 BlockOf(const RunSums& s, const Vec3& n0) {
  Mat6 A = Eigen::Map<const RowMajor6>(s.normal_block) + Eigen::Map<const RowMajor6>(s.slip_block);
  auto moments = [](const double* m, Mat3* m2) {
    *m2 << m[4], m[5], m[6], m[5], m[7], m[8], m[6], m[8], m[9];
    return Vec3(m[1], m[2], m[3]);
  };
  Mat3 m2;
  Vec3 m1 = moments(s.isotropic, &m2);
  A.topLeftCorner<3, 3>() += m2.trace() * Mat3::Identity() - m2;
  A.topRightCorner<3, 3>() += Skew(m1);
  A.bottomLeftCorner<3, 3>() -= Skew(m1);
  A.bottomRightCorner<3, 3>().diagonal().array() += s.isotropic[0];
  m1 = moments(s.along, &m2);
  const Mat3 N = Skew(n0);
  A.topLeftCorner<3, 3>() += N * m2 * N.transpose();
  A.topRightCorner<3, 3>() += m1.cross(n0) * n0.transpose();
  A.bottomLeftCorner<3, 3>() += n0 * m1.cross(n0).transpose();
  A.bottomRightCorner<3, 3>() += s.along[0] * n0 * n0.transpose();
  return A;
}

Mat6 ScalarBlock(const ContactForce& f, const Vec3& p, const Vec3& n, double h) {
  Eigen::Matrix<double, 3, 6> e;
  e << -Skew(p), Mat3::Identity();
  const Mat3 K = f.Stiffness() + f.k_slip_normal * f.slip_direction * n.transpose();
  const Mat3 D = f.Damping() + f.d_slip_normal * f.slip_direction * n.transpose();
  return e.transpose() * (h * D + h * h * K) * e;
}

void ExpectKernelMatchesLaw(bool use_avx2, bool shared_normal, const double (&twist)[6], bool step_end_normal) {
  const Contacts c = MakeContacts(shared_normal);
  ContactRun run = RunOf(c, twist);
  run.step_end_normal = step_end_normal;
  const size_t n = run.count;
  std::vector<double> fx(n), fy(n), fz(n), fn(n), zx(n), zy(n), zz(n);
  RunSums sums;
#if defined(__x86_64__)
  if (use_avx2) {
    contact_kernel::avx2::EvaluateRun(run, true, fx.data(), fy.data(), fz.data(), fn.data(), &sums);
    contact_kernel::avx2::AdvanceRun(run, fn.data(), zx.data(), zy.data(), zz.data());
  }
#endif
  if (!use_avx2) {
    contact_kernel::generic::EvaluateRun(run, true, fx.data(), fy.data(), fz.data(), fn.data(), &sums);
    contact_kernel::generic::AdvanceRun(run, fn.data(), zx.data(), zy.data(), zz.data());
  }
  Vec3 force = Vec3::Zero(), moment = Vec3::Zero();
  Mat6 block = Mat6::Zero();
  const Vec3 omega(twist[0], twist[1], twist[2]), velocity(twist[3], twist[4], twist[5]);
  for (size_t i = 0; i < n; ++i) {
    const Vec3 v = velocity + omega.cross(c.point[i]);
    const ContactForce f = EvaluateContact(run.law, c.depth[i], c.normal[i], v, c.bristle[i], run.h);
    const double scale = 1e-9 * (1 + f.force.norm());
    EXPECT_NEAR(fx[i], f.force.x(), scale) << i;
    EXPECT_NEAR(fy[i], f.force.y(), scale) << i;
    EXPECT_NEAR(fz[i], f.force.z(), scale) << i;
    EXPECT_NEAR(fn[i], f.normal_force, scale) << i;
    force += f.force;
    moment += c.point[i].cross(f.force);
    block += ScalarBlock(f, c.point[i], c.normal[i], run.h);
    const double advancing = step_end_normal
                                 ? StepEndNormalForce(run.law, f.normal_force, c.depth[i], c.normal[i], v, run.h)
                                 : f.normal_force;
    const Vec3 z = AdvanceBristle(run.law, advancing, c.normal[i], v, c.bristle[i], run.h);
    EXPECT_NEAR(zx[i], z.x(), 1e-12) << i;
    EXPECT_NEAR(zy[i], z.y(), 1e-12) << i;
    EXPECT_NEAR(zz[i], z.z(), 1e-12) << i;
  }
  EXPECT_LT((Vec3(sums.force) - force).norm(), 1e-9 * (1 + force.norm()));
  EXPECT_LT((Vec3(sums.moment) - moment).norm(), 1e-9 * (1 + moment.norm()));
  EXPECT_LT((BlockOf(sums, c.normal[0]) - block).norm(), 1e-9 * (1 + block.norm()));
}

// Sticking (µm/s), the Stribeck drop (mm/s) and sliding (0.1 m/s), spinning about the pair's axis too.
constexpr double kSticking[6] = {0, 0, 1e-4, 1e-6, -2e-6, 0};
constexpr double kDrop[6] = {0.01, 0, 0, 1e-3, 2e-3, -1e-4};
constexpr double kSliding[6] = {0.3, -0.2, 1, 0.1, -0.05, 0.002};

TEST(ContactKernelTest, GenericBuildMatchesTheScalarLaw) {
  for (bool shared : {true, false}) {
    for (const auto* twist : {&kSticking, &kDrop, &kSliding}) {
      for (bool step_end_normal : {false, true}) ExpectKernelMatchesLaw(false, shared, *twist, step_end_normal);
    }
  }
}

TEST(ContactKernelTest, Avx2BuildMatchesTheScalarLaw) {
#if defined(__x86_64__)
  __builtin_cpu_init();
  if (!__builtin_cpu_supports("avx2") || !__builtin_cpu_supports("fma")) GTEST_SKIP() << "no AVX2 + FMA";
  for (bool shared : {true, false}) {
    for (const auto* twist : {&kSticking, &kDrop, &kSliding}) {
      for (bool step_end_normal : {false, true}) ExpectKernelMatchesLaw(true, shared, *twist, step_end_normal);
    }
  }
#else
  GTEST_SKIP() << "x86-64 only";
#endif
}

}  // namespace
}  // namespace graspsim
