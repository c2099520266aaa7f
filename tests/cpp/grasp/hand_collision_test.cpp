// The approach-path and self-collision checks: the swept-box test against placing the box at many points of its
// path, a candidate whose way to the object crosses an obstacle (but whose grasp pose does not) discarded, and
// closed fingers overlapping each other found as sampling the link surfaces finds them.
#include <random>

#include <gtest/gtest.h>

#include "grasp/grasp_fixtures.h"
#include "grasp/hand_collision.h"
#include "grasp/planner.h"

namespace graspsim::grasp {
namespace {

using testing::ToMesh;

LinkBox RandomBox(std::mt19937_64& random) {
  std::uniform_real_distribution<double> u(-1, 1), size(0.005, 0.05);
  LinkBox b;
  b.centre = 0.05 * Vec3(u(random), u(random), u(random));
  b.axes = Eigen::Quaterniond(u(random), u(random), u(random), u(random)).normalized().toRotationMatrix();
  b.half = Vec3(size(random), size(random), size(random));
  return b;
}

TEST(GraspHandCollisionTest, SweptBoxMatchesTheBoxPlacedAlongItsPath) {
  std::mt19937_64 random(11);
  std::uniform_real_distribution<double> u(-1, 1);
  int overlapping = 0, separate = 0;
  for (int trial = 0; trial < 400; ++trial) {
    const LinkBox a = RandomBox(random), b = RandomBox(random);
    const Vec3 motion = 0.2 * Vec3(u(random), u(random), u(random));
    // Placed at 2001 points of the path: steps of at most 0.17 mm.
    bool touched = false, deep = false;
    for (int k = 0; k <= 2000; ++k) {
      const LinkBox moved{a.centre + motion * (k / 2000.0), a.axes, a.half};
      touched = touched || BoxesOverlap(moved, b, 0.0);
      deep = deep || BoxesOverlap(moved, b, -1e-3);
    }
    // Exact sweep: every placed overlap is found; whatever it finds overlaps somewhere by the step's margin.
    if (touched) {
      EXPECT_TRUE(SweptBoxOverlaps(a, motion, b, 0.0)) << trial;
    }
    if (SweptBoxOverlaps(a, motion, b, -1e-3)) {
      EXPECT_TRUE(touched) << trial;
    }
    if (!SweptBoxOverlaps(a, motion, b, 0.0)) {
      EXPECT_FALSE(deep) << trial;
    }
    (touched ? overlapping : separate)++;
  }
  EXPECT_GT(overlapping, 50);
  EXPECT_GT(separate, 50);
}

TEST(GraspHandCollisionTest, ApproachThroughAnObstacleIsDiscarded) {
  // The PG70 comes along -x onto a 5 cm cube at the origin; its grasp pose spans x in [0.025, ~0.13]. A bar at
  // x = 0.2 is not touched there but lies on the way from far back: the candidate is a collision. The same bar
  // beside the path, or behind where the approach starts, changes nothing.
  auto cube = ToMesh(collision::BoxMesh(Vec3::Constant(0.025)));
  Candidate c;
  c.approach = -Vec3::UnitX();
  c.target = Vec3(0.025, 0, 0);
  c.reference = Vec3::UnitZ();
  auto evaluate = [&](const Vec3& bar_centre, PlannedGrasp* grasp) {
    const LinkBox bar{bar_centre, Mat3::Identity(), Vec3(0.01, 0.1, 0.1)};
    const GraspPlanner planner("schunk_pg70", cube, {bar}, ClosingParams());
    return planner.Evaluate(c, grasp);
  };
  PlannedGrasp free, through, beside, behind;
  ASSERT_EQ(evaluate(Vec3(0, 0, 5), &free), Outcome::kGrasp);
  EXPECT_EQ(evaluate(Vec3(0.2, 0, 0), &through), Outcome::kCollision);
  EXPECT_EQ(evaluate(Vec3(0.2, 0.3, 0), &beside), Outcome::kGrasp);
  EXPECT_EQ(evaluate(Vec3(0.6, 0, 0), &behind), Outcome::kGrasp);
  // The grasp pose itself is clear of the bar: only the way there is blocked.
  const GraspPlanner planner("schunk_pg70", cube, {}, ClosingParams());
  std::vector<Pose> poses(planner.hand().links().size());
  planner.hand().LinkPoses(through.hand_pose, planner.hand().PreshapeJoints(0), &poses);
  EXPECT_FALSE(HandOverlapsObstacles(planner.hand(), poses, Vec3::Zero(),
                                     {LinkBox{Vec3(0.2, 0, 0), Mat3::Identity(), Vec3(0.01, 0.1, 0.1)}}, -1e-3));
  EXPECT_NEAR(through.hand_pose.position.x(), free.hand_pose.position.x(), 1e-9);
}

// Independent reference: a sample of one link's surface more than `depth` inside a box of another link.
bool SamplesInside(const HandModel& hand, const std::vector<Pose>& poses, int l, int m, double depth) {
  for (const Vec3& s : hand.links()[l].samples) {
    const Vec3 p = poses[l] * s;
    for (const LinkBox& box : hand.links()[m].boxes) {
      const Vec3 local = box.axes.transpose() * (poses[m].Inverse() * p - box.centre);
      if (((box.half.array() - depth) - local.cwiseAbs().array()).minCoeff() > 0) return true;
    }
  }
  return false;
}

TEST(GraspHandCollisionTest, ClosedFingersOverlappingEachOtherAreFound) {
  auto cube = ToMesh(collision::BoxMesh(Vec3::Constant(0.025)));
  for (const char* name : {"schunk_pg70", "barrett_bh8_282", "schunk_sdh2"}) {
    const GraspPlanner planner(name, cube, {}, ClosingParams());
    const HandModel& hand = planner.hand();
    const SelfCollision self(hand, -1e-3);
    std::vector<Pose> poses(hand.links().size());
    int found = 0;
    for (size_t p = 0; p < hand.preshape_names().size(); ++p) {
      hand.LinkPoses(Pose(), hand.PreshapeJoints(p), &poses);
      EXPECT_FALSE(self.Collides(poses)) << name << " open in " << hand.preshape_names()[p];
      // Every finger closed by the same fraction of its range, from nearly open to fully closed.
      for (int step = 1; step <= 10; ++step) {
        std::vector<double> q = hand.PreshapeJoints(p);
        for (size_t f = 0; f < hand.fingers().size(); ++f) {
          const double s = hand.ClosingRange(f, hand.PreshapeJoints(p)) * step / 10.0;
          for (const auto& [j, rate] : hand.fingers()[f].joint_rates) q[j] += rate * s;
        }
        hand.LinkPoses(Pose(), q, &poses);
        bool reference = false;
        for (const auto& [l, m] : self.pairs()) {
          reference = reference || SamplesInside(hand, poses, l, m, 2e-3) || SamplesInside(hand, poses, m, l, 2e-3);
        }
        const bool collides = self.Collides(poses);
        if (reference) {
          EXPECT_TRUE(collides) << name << " " << p << " " << step;
        }
        found += collides;
      }
    }
    // The PG70's jaws stop 1 cm apart; the Barrett's and the SDH's fingers meet when they close on nothing.
    if (std::string(name) == "schunk_pg70") {
      EXPECT_EQ(found, 0);
    } else {
      EXPECT_GT(found, 0) << name;
      EXPECT_FALSE(self.pairs().empty()) << name;
    }
  }
}

}  // namespace
}  // namespace graspsim::grasp
