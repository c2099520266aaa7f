// Planned paths never collide (dense re-check with the exact geometry at <= 1 mm of end-effector travel),
// respect the joint limits and the velocity and acceleration limits in time; blocked or unreachable goals and
// colliding starts are FAILED_PRECONDITION with the reason; same seed, same path.
#include <random>

#include <gtest/gtest.h>

#include "motion/exact_checker.h"
#include "motion/planner.h"
#include "motion_test_scenes.h"
#include "test_util.h"

namespace graspsim::motion {
namespace {

using namespace motion_test;
using test_util::ExpectError;

struct Fixture {
  explicit Fixture(const std::string& model)
      : s(TableScene(model)),
        arm(*s.view.model, s.view.state, "arm"),
        checker(arm, BuildSphereModel(*s.view.model, arm), CollectObstacles(*s.view.model, s.view.state, "arm")),
        exact(*s.view.model, s.view.state, arm, checker.spheres(), {}, 0.003) {}
  ArmScene s;
  ArmModel arm;
  CollisionChecker checker;
  ExactChecker exact;

  VecX RandomFree(std::mt19937_64* rng) const {
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    VecX q(arm.dof());
    do {
      for (size_t j = 0; j < arm.dof(); ++j) q[j] = arm.lower()[j] + unit(*rng) * (arm.upper()[j] - arm.lower()[j]);
    } while (!checker.IsValid(q));
    return q;
  }

  // Walks every segment in steps that move the tip at most 1 mm and checks each configuration exactly.
  // Returns the number of configurations checked.
  size_t DenseRecheck(const std::vector<VecX>& path) const {
    size_t checked = 0;
    for (size_t k = 0; k + 1 < path.size(); ++k) {
      const VecX& a = path[k];
      const VecX& b = path[k + 1];
      double t = 0, dt = 1e-3;
      Vec3 tip = arm.TipPose(a).position;
      while (t < 1) {
        double next = std::min(1.0, t + dt);
        VecX q = a + next * (b - a);
        Vec3 tip_next = arm.TipPose(q).position;
        while ((tip_next - tip).norm() > 1e-3) {  // too far: halve the step
          dt *= 0.5;
          next = std::min(1.0, t + dt);
          q = a + next * (b - a);
          tip_next = arm.TipPose(q).position;
        }
        EXPECT_TRUE(arm.WithinLimits(q));
        const std::string why = exact.Explain(q);
        EXPECT_EQ(why, "") << "segment " << k << " t " << next << " q " << q.transpose();
        if (!why.empty()) return checked;
        ++checked;
        t = next;
        tip = tip_next;
        dt *= 1.5;
      }
    }
    return checked;
  }
};

void ExpectWithinDynamicLimits(const ArmModel& arm, const Trajectory& trajectory) {
  const VecX acceleration = 2.0 * arm.velocity_limits();  // PlanOptions' default
  ASSERT_GT(trajectory.duration(), 0);
  for (int i = 0; i <= 2000; ++i) {
    const double t = trajectory.duration() * i / 2000;
    const VecX v = trajectory.Velocity(t), a = trajectory.Acceleration(t);
    for (size_t j = 0; j < arm.dof(); ++j) {
      EXPECT_LE(std::abs(v[j]), arm.velocity_limits()[j] * (1 + 1e-9)) << "t " << t << " joint " << j;
      EXPECT_LE(std::abs(a[j]), acceleration[j] * (1 + 1e-9)) << "t " << t << " joint " << j;
    }
    EXPECT_TRUE(arm.WithinLimits(trajectory.Position(t), 1e-12));
  }
  // It passes through every waypoint at its time, at rest.
  for (size_t k = 0; k < trajectory.waypoints().size(); ++k) {
    EXPECT_LT((trajectory.Position(trajectory.times()[k]) - trajectory.waypoints()[k]).norm(), 1e-12);
    EXPECT_LT(trajectory.Velocity(trajectory.times()[k]).norm(), 1e-9);
  }
}

TEST(MotionPlannerTest, PathsBetweenRandomConfigurationsNeverCollide) {
  for (const char* model : {"kuka_kr5_sixx_r850_barrett", "mitsubishi_pa10_pg70"}) {
    Fixture f(model);
    std::mt19937_64 rng(23);
    int searched = 0;
    for (int problem = 0; problem < 3; ++problem) {
      const VecX start = f.RandomFree(&rng), goal = f.RandomFree(&rng);
      PlanOptions options;
      options.seed = problem + 1;
      options.try_direct = problem % 2 == 0;  // half of them searched by RRT-Connect whatever the straight line
      const PlanResult plan = PlanPath(f.checker, start, {goal}, options);
      ASSERT_GE(plan.path.size(), 2u);
      EXPECT_EQ(plan.path.front(), start);
      EXPECT_EQ(plan.path.back(), goal);
      EXPECT_LE(plan.path.size(), plan.raw_waypoints);
      searched += !plan.direct;
      EXPECT_GT(f.DenseRecheck(plan.path), 10u) << model;
      ExpectWithinDynamicLimits(f.arm, plan.trajectory);
    }
    EXPECT_GT(searched, 0) << model << ": every problem was a straight line; the test would not see the search";
  }
}

TEST(MotionPlannerTest, SmallShortcutsAreNotCheckedAndThePathStaysAsShort) {
  // Random shortcuts that would shorten the path by less than 0.5 % of it are not checked. Over 6 searched
  // problems: fewer configurations tested than when every attempt is checked, a total length within 1 % of it
  // (MotionBenchMaker's 700: −26 % configurations, the same mean length).
  Fixture f("kuka_kr5_sixx_r850_barrett");
  std::mt19937_64 rng(5);
  double length[2] = {0, 0};
  uint64_t checks[2] = {0, 0};
  for (int problem = 0; problem < 6; ++problem) {
    const VecX start = f.RandomFree(&rng), goal = f.RandomFree(&rng);
    for (int every = 0; every < 2; ++every) {
      PlanOptions options;
      options.seed = problem + 1;
      options.try_direct = false;
      options.shortcut_rounds = 48;
      if (every == 1) options.shortcut_min_gain = 0;
      const PlanResult plan = PlanPath(f.checker, start, {goal}, options);
      for (size_t k = 1; k < plan.path.size(); ++k) length[every] += (plan.path[k] - plan.path[k - 1]).norm();
      checks[every] += plan.checks;
    }
  }
  EXPECT_LT(checks[0], checks[1]);
  EXPECT_LT(length[0], 1.01 * length[1]);
}

TEST(MotionPlannerTest, ReachesAGoalPoseAcrossThePost) {
  Fixture f("kuka_kr5_sixx_r850_barrett");
  // The flange facing down 50 cm above the table left of the post (the Barrett's fingertips 24 cm above it,
  // below the post's top), to the same right of it (a straight Cartesian move would run the fingers through the
  // post).
  const Pose goal{Vec3(0.0, -0.2, 1.25), Quat(Eigen::AngleAxisd(EIGEN_PI, Vec3::UnitY()))};
  IkOptions ik;
  ik.near = VecX::Zero(6);
  const IkResult left = SolveIk(f.arm, Pose{Vec3(0.0, 0.2, 1.25), goal.orientation}, ik);
  ASSERT_FALSE(left.solutions.empty()) << left.failure;
  VecX start = left.solutions.front();
  ASSERT_TRUE(f.checker.IsValid(start)) << f.checker.Explain(start);
  const PlanResult plan = PlanPathToPose(f.checker, start, goal);
  const Pose reached = f.arm.TipPose(plan.path.back());
  EXPECT_LT((reached.position - goal.position).norm(), 1e-9);
  EXPECT_LT(reached.orientation.angularDistance(goal.orientation), 1e-9);
  f.DenseRecheck(plan.path);
  ExpectWithinDynamicLimits(f.arm, plan.trajectory);
}

TEST(MotionPlannerTest, BlockedGoalsAreFailedPreconditionWithTheReason) {
  Fixture f("kuka_kr5_sixx_r850_barrett");
  const VecX start = VecX::Zero(6);
  // The palm inside the post: every IK solution collides.
  const Pose inside{Vec3(0.0, 0.0, 0.95), Quat(Eigen::AngleAxisd(EIGEN_PI, Vec3::UnitY()))};
  ExpectError([&] { PlanPathToPose(f.checker, start, inside); }, ErrorCode::kFailedPrecondition,
              {"goal pose unreachable: all ", " IK solutions collide (first: arm/", " touches post"});
  ExpectError([&] { PlanPathToPose(f.checker, start, Pose{Vec3(1.5, 0, 0.9), Quat::Identity()}); },
              ErrorCode::kFailedPrecondition, {"goal pose unreachable: target out of reach"});
  VecX down = VecX::Zero(6);
  down[1] = 2.2;  // the upper arm down through the table
  ExpectError([&] { PlanPath(f.checker, start, {down}); }, ErrorCode::kFailedPrecondition,
              {"goal unreachable: the goal configuration is blocked: arm/"});
  ExpectError([&] { PlanPath(f.checker, down, {start}); }, ErrorCode::kFailedPrecondition,
              {"start configuration is not free: arm/"});
  ExpectError([&] { PlanPath(f.checker, VecX::Zero(5), {start}); }, ErrorCode::kInvalidArgument,
              {"start: 5 joint positions for an arm of 6"});
  VecX nan = start;
  nan[2] = NAN;
  ExpectError([&] { PlanPath(f.checker, start, {nan}); }, ErrorCode::kInvalidArgument, {"goal[2] is not finite"});
}

TEST(MotionPlannerTest, SameSeedSamePathAndCancellationStops) {
  Fixture f("mitsubishi_pa10_pg70");
  std::mt19937_64 rng(5);
  VecX start, goal;
  PlanOptions options;
  options.try_direct = false;  // always search
  options.seed = 9;
  start = f.RandomFree(&rng);
  goal = f.RandomFree(&rng);
  const PlanResult a = PlanPath(f.checker, start, {goal}, options);
  const PlanResult b = PlanPath(f.checker, start, {goal}, options);
  ASSERT_EQ(a.path.size(), b.path.size());
  for (size_t k = 0; k < a.path.size(); ++k) EXPECT_EQ(a.path[k], b.path[k]);
  options.cancelled = [] { return true; };
  const PlanResult cancelled = PlanPath(f.checker, start, {goal}, options);
  EXPECT_TRUE(cancelled.cancelled);
  EXPECT_TRUE(cancelled.path.empty());
}

}  // namespace
}  // namespace graspsim::motion
