// PlanArmPath's job on a scene without gRPC (motion/arm_path_request.h): the request's refusals name the field and
// the value; a plan between two free configurations of the KR 5 on its table, and one to a tip pose, start at the
// start and end at the goal; the tip path for the viewer runs from the start's tip to the goal's, in small steps,
// and is computed only when asked for.
#include "motion/arm_path_request.h"

#include <cmath>
#include <random>

#include <gtest/gtest.h>

#include "motion/sphere_model.h"
#include "motion_test_scenes.h"
#include "test_util.h"

namespace graspsim::motion {
namespace {

using test_util::ExpectError;

std::vector<double> Values(const VecX& q) { return {q.data(), q.data() + q.size()}; }

class ArmPathRequestTest : public ::testing::Test {
 protected:
  ArmPathRequestTest()
      : s_(motion_test::TableScene("kuka_kr5_sixx_r850")),
        arm_(*s_.view.model, s_.view.state, "arm"),
        checker_(arm_, BuildSphereModel(*s_.view.model, arm_), CollectObstacles(*s_.view.model, s_.view.state, "arm")) {}

  VecX RandomFree(std::mt19937_64* rng) const {
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    VecX q(arm_.dof());
    do {
      for (size_t j = 0; j < arm_.dof(); ++j) q[j] = arm_.lower()[j] + unit(*rng) * (arm_.upper()[j] - arm_.lower()[j]);
    } while (!checker_.IsValid(q));
    return q;
  }
  ArmPathRequest Request(const VecX& start, const VecX& goal) const {
    ArmPathRequest r;
    r.arm_id = "arm";
    r.start_positions = Values(start);
    r.goal_positions = Values(goal);
    return r;
  }

  motion_test::ArmScene s_;
  ArmModel arm_;
  CollisionChecker checker_;
};

TEST_F(ArmPathRequestTest, RefusalsNameTheField) {
  std::mt19937_64 rng(3);
  const VecX start = RandomFree(&rng), goal = RandomFree(&rng);
  const auto refused = [&](auto change, std::initializer_list<const char*> parts) {
    ArmPathRequest r = Request(start, goal);
    change(r);
    ExpectError([&] { PlanArmPathInScene(s_.view, r); }, ErrorCode::kInvalidArgument, parts);
  };
  refused([](auto& r) { r.arm_id = ""; }, {"arm_id: empty"});
  refused([](auto& r) { r.goal_positions.clear(); }, {"goal: absent; give a goal pose or goal_positions"});
  refused([](auto& r) { r.goal = Pose(); }, {"goal, goal_positions: both given; give one"});
  refused([](auto& r) { r.timeout = 100; }, {"timeout: 100 s is outside [0, 60]"});
  refused([](auto& r) { r.timeout = NAN; }, {"timeout: nan s"});
  refused([](auto& r) { r.planner = "bogus"; }, {"planner: 'bogus' is not a planner"});
  refused([](auto& r) { r.start_positions = {0, 0}; }, {"start_positions: 2 values for the 6 joints of arm 'arm'"});
  refused([](auto& r) { r.goal_positions[4] = INFINITY; }, {"goal_positions[4]: inf is not finite"});
  EXPECT_EQ(ParsePlanner("planner", ""), Planner::kRrtConnect);
  EXPECT_STREQ(PlannerName(ParsePlanner("planner", "ompl_rrt_connect")), "ompl_rrt_connect");
}

TEST_F(ArmPathRequestTest, APathRunsFromTheStartToTheGoalAndItsTipPathWithIt) {
  std::mt19937_64 rng(11);
  const VecX start = RandomFree(&rng), goal = RandomFree(&rng);
  ArmPathRequest request = Request(start, goal);
  request.planner = "ompl_rrt_connect";
  const ArmPathPlan plain = PlanArmPathInScene(s_.view, request);
  EXPECT_EQ(plain.joint_ids, arm_.joint_ids());
  EXPECT_EQ(plain.tip_body, "arm/flange");
  EXPECT_EQ(plain.planner, Planner::kOmplRrtConnect);
  EXPECT_TRUE(plain.tip_path.empty());  // not asked for
  const auto& waypoints = plain.result.trajectory.waypoints();
  ASSERT_GE(waypoints.size(), 2u);
  EXPECT_EQ(waypoints.front(), start);
  EXPECT_LT((waypoints.back() - goal).norm(), 1e-9);

  request.tip_path = true;
  const ArmPathPlan with_tip = PlanArmPathInScene(s_.view, request);
  const std::vector<Vec3>& tip = with_tip.tip_path;
  ASSERT_GE(tip.size(), 2u);
  EXPECT_LT((tip.front() - arm_.TipPose(start).position).norm(), 1e-12);
  EXPECT_LT((tip.back() - arm_.TipPose(goal).position).norm(), 1e-9);
  // Sampled along each segment, so the drawn path follows the curve the tip takes between waypoints.
  EXPECT_GT(tip.size(), with_tip.result.trajectory.waypoints().size());
  for (size_t i = 1; i < tip.size(); ++i) EXPECT_LT((tip[i] - tip[i - 1]).norm(), 0.5) << i;
}

TEST_F(ArmPathRequestTest, AGoalPoseIsReachedByTheTip) {
  std::mt19937_64 rng(5);
  const VecX start = RandomFree(&rng), target = RandomFree(&rng);
  ArmPathRequest request = Request(start, target);
  request.goal_positions.clear();
  request.goal = arm_.TipPose(target);
  request.seed = 4;
  const ArmPathPlan plan = PlanArmPathInScene(s_.view, request);
  const Pose reached = arm_.TipPose(plan.result.trajectory.waypoints().back());
  EXPECT_LT((reached.position - request.goal->position).norm(), 1e-4);
  EXPECT_LT(reached.orientation.angularDistance(request.goal->orientation), 1e-3);
}

}  // namespace
}  // namespace graspsim::motion
