// Arm kinematics against the datasheets, and IK: every solution reproduces the target through FK to 1e-9,
// lies within the joint limits, the closed form finds all of the KR 5's, and unreachable targets say why.
#include <random>

#include <gtest/gtest.h>

#include "motion/ik.h"
#include "motion_test_scenes.h"

namespace graspsim::motion {
namespace {

using motion_test::MakeArmScene;

VecX RandomWithin(const ArmModel& arm, std::mt19937_64* rng) {
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  VecX q(arm.dof());
  for (size_t i = 0; i < arm.dof(); ++i) q[i] = arm.lower()[i] + unit(*rng) * (arm.upper()[i] - arm.lower()[i]);
  return q;
}

double PoseDistance(const Pose& a, const Pose& b) {
  return (a.position - b.position).norm() + a.orientation.angularDistance(b.orientation);
}

TEST(MotionArmTest, Kr5FlangeAtTheDatasheetDimensions) {
  const auto s = MakeArmScene("kuka_kr5_sixx_r850");
  const ArmModel arm(*s.view.model, s.view.state, "arm");
  ASSERT_EQ(arm.dof(), 6u);
  EXPECT_EQ(arm.joint_ids().front(), "arm/joint_a1");
  EXPECT_EQ(arm.tip_body(), "arm/flange");
  // q = 0: A2 335 mm up and 75 mm ahead; upper arm 365; A4 35 above A3; forearm 405; flange 80 ahead of A5.
  const Pose zero = arm.TipPose(VecX::Zero(6));
  EXPECT_LT((zero.position - Vec3(0.075 + 0.405 + 0.080, 0, 0.335 + 0.365 + 0.035)).norm(), 1e-12);
  EXPECT_LT((zero.orientation * Vec3::UnitZ() - Vec3::UnitX()).norm(), 1e-12);  // the flange faces +x
  // A1 +-170 deg, A5 +-120 deg, A6 +-358 deg; A1 375 deg/s.
  EXPECT_NEAR(arm.upper()[0], 170 * EIGEN_PI / 180, 1e-12);
  EXPECT_NEAR(arm.upper()[4], 120 * EIGEN_PI / 180, 1e-12);
  EXPECT_NEAR(arm.upper()[5], 358 * EIGEN_PI / 180, 1e-12);
  EXPECT_NEAR(arm.velocity_limits()[0], 375 * EIGEN_PI / 180, 1e-12);
}

TEST(MotionArmTest, Pa10StretchedUpReachesTheSumOfItsDhLengths) {
  const auto s = MakeArmScene("mitsubishi_pa10");
  const ArmModel arm(*s.view.model, s.view.state, "arm");
  ASSERT_EQ(arm.dof(), 7u);
  const Pose zero = arm.TipPose(VecX::Zero(7));
  EXPECT_LT((zero.position - Vec3(0, 0, 0.317 + 0.450 + 0.480 + 0.070)).norm(), 1e-12);
  // Bending S2 by 90 deg lays the rest of the arm along +x at the shoulder's height.
  VecX q = VecX::Zero(7);
  q[1] = EIGEN_PI / 2;
  EXPECT_LT((arm.TipPose(q).position - Vec3(0.45 + 0.48 + 0.07, 0, 0.317)).norm(), 1e-12);
}

TEST(MotionArmTest, MountedHandRidesOnTheFlange) {
  const auto s = MakeArmScene("kuka_kr5_sixx_r850_barrett");
  const ArmModel flange(*s.view.model, s.view.state, "arm");
  const ArmModel palm(*s.view.model, s.view.state, "arm", "arm/palm");
  EXPECT_EQ(flange.dof(), 6u);  // the fingers are held, not planned
  EXPECT_EQ(palm.dof(), 6u);
  std::mt19937_64 rng(3);
  for (int i = 0; i < 20; ++i) {
    const VecX q = RandomWithin(flange, &rng);
    EXPECT_LT(PoseDistance(flange.TipPose(q), palm.TipPose(q)), 1e-12);  // identity mount
  }
  EXPECT_GT(flange.links().size(), 8u);  // arm links + palm + fingers
}

TEST(MotionArmTest, JacobianMatchesFiniteDifferences) {
  for (const char* model : {"kuka_kr5_sixx_r850_pg70", "mitsubishi_pa10_sdh2"}) {
    const auto s = MakeArmScene(model);
    const ArmModel arm(*s.view.model, s.view.state, "arm", "");
    std::mt19937_64 rng(5);
    const VecX q = RandomWithin(arm, &rng);
    const auto jacobian = arm.Jacobian(q);
    const double h = 1e-6;
    for (size_t i = 0; i < arm.dof(); ++i) {
      VecX qp = q, qm = q;
      qp[i] += h;
      qm[i] -= h;
      const Rigid p = arm.TipTransform(qp), m = arm.TipTransform(qm);
      const Vec3 linear = (p.translation - m.translation) / (2 * h);
      const Eigen::AngleAxisd turn(p.rotation * m.rotation.transpose());
      const Vec3 angular = turn.angle() * turn.axis() / (2 * h);
      EXPECT_LT((linear - jacobian.col(i).head<3>()).norm(), 1e-7) << model << " dof " << i;
      EXPECT_LT((angular - jacobian.col(i).tail<3>()).norm(), 1e-7) << model << " dof " << i;
    }
  }
}

TEST(MotionIkTest, Kr5ClosedFormFindsEverySolutionExactly) {
  const auto s = MakeArmScene("kuka_kr5_sixx_r850_barrett", Pose{Vec3(0.1, -0.2, 0.75), Quat::Identity()});
  const ArmModel arm(*s.view.model, s.view.state, "arm", "arm/palm");
  ASSERT_TRUE(SphericalWristIk::Detect(arm).has_value());
  std::mt19937_64 rng(11);
  size_t total = 0;
  for (int trial = 0; trial < 200; ++trial) {
    const VecX truth = RandomWithin(arm, &rng);
    const Pose target = arm.TipPose(truth);
    const IkResult ik = SolveIk(arm, target);
    ASSERT_TRUE(ik.analytic);
    ASSERT_FALSE(ik.solutions.empty()) << ik.failure;
    bool found_truth = false;
    for (const VecX& q : ik.solutions) {
      EXPECT_TRUE(arm.WithinLimits(q)) << q.transpose();
      const Pose reached = arm.TipPose(q);
      EXPECT_LT((reached.position - target.position).norm(), 1e-9);
      EXPECT_LT(reached.orientation.angularDistance(target.orientation), 1e-9);
      found_truth |= (q - truth).norm() < 1e-6;
    }
    // The configuration the target came from is among the solutions (unless the wrist is singular).
    EXPECT_TRUE(found_truth || std::abs(std::sin(truth[4])) < 1e-6) << truth.transpose();
    total += ik.solutions.size();
  }
  EXPECT_GT(total, 200u * 2);  // a generic KR 5 pose has several solutions (2 wrist flips at least)
}

TEST(MotionIkTest, Pa10DampedLeastSquaresReachesRandomPosesExactly) {
  const auto s = MakeArmScene("mitsubishi_pa10_pg70");
  const ArmModel arm(*s.view.model, s.view.state, "arm");
  EXPECT_FALSE(SphericalWristIk::Detect(arm).has_value());
  std::mt19937_64 rng(13);
  for (int trial = 0; trial < 40; ++trial) {
    const VecX truth = RandomWithin(arm, &rng);
    const Pose target = arm.TipPose(truth);
    IkOptions options;
    options.seed = trial + 1;
    options.max_solutions = 3;
    const IkResult ik = SolveIk(arm, target, options);
    ASSERT_FALSE(ik.analytic);
    ASSERT_FALSE(ik.solutions.empty()) << ik.failure;
    for (const VecX& q : ik.solutions) {
      EXPECT_TRUE(arm.WithinLimits(q));
      const Pose reached = arm.TipPose(q);
      EXPECT_LT((reached.position - target.position).norm(), 1e-9);
      EXPECT_LT(reached.orientation.angularDistance(target.orientation), 1e-9);
    }
  }
}

TEST(MotionIkTest, UnreachableTargetsSayWhy) {
  const auto kr5 = MakeArmScene("kuka_kr5_sixx_r850");
  const ArmModel arm6(*kr5.view.model, kr5.view.state, "arm");
  const IkResult far = SolveIk(arm6, Pose{Vec3(2.0, 0, 0.5), Quat::Identity()});
  EXPECT_TRUE(far.solutions.empty());
  EXPECT_NE(far.failure.find("out of reach"), std::string::npos) << far.failure;
  // Behind the base, flange facing back: every solution needs A1 at 180 deg (limit 170) or worse.
  const Pose back{Vec3(-0.2, 0, 0.5), Quat(Eigen::AngleAxisd(-EIGEN_PI / 2, Vec3::UnitY()))};
  const IkResult limits = SolveIk(arm6, back);
  EXPECT_TRUE(limits.solutions.empty());
  EXPECT_NE(limits.failure.find("joint limits"), std::string::npos) << limits.failure;

  const auto pa10 = MakeArmScene("mitsubishi_pa10");
  const ArmModel arm7(*pa10.view.model, pa10.view.state, "arm");
  IkOptions options;
  options.restarts = 4;
  const IkResult far7 = SolveIk(arm7, Pose{Vec3(0, 0, 3.0), Quat::Identity()}, options);
  EXPECT_TRUE(far7.solutions.empty());
  EXPECT_NE(far7.failure.find("out of reach"), std::string::npos) << far7.failure;
}

}  // namespace
}  // namespace graspsim::motion
