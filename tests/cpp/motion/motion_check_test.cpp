// CollisionChecker::IsMotionValid is conservative (collision_checker.h): a segment it accepts touches nothing
// anywhere, checked by walking it so densely that no sphere centre moves more than 0.5 mm between samples, each
// sample tested by the double-precision reference (sphere_reference.h). Ends closer to an obstacle than the first
// round's spacing are refined, so a motion that leaves a tight spot is accepted; a motion into an obstacle is not.
#include <cstdio>
#include <random>
#include <stdexcept>

#include <gtest/gtest.h>

#include "motion/collision_checker.h"
#include "sphere_reference.h"

namespace graspsim::motion {
namespace {

using namespace motion_test;

constexpr double kStep = 5e-4;  // m, the most a sphere centre moves between two samples of the dense walk

struct Walk {
  double min_clearance = INFINITY;  // m, over every sample
  double max_step = 0;              // m, the largest centre displacement between two samples
  size_t samples = 0;
};

// Samples a -> b so that no sphere centre moves more than kStep between two samples.
Walk DenseWalk(const SphereReference& reference, const VecX& a, const VecX& b) {
  Walk walk;
  std::vector<Vec3> before, after;
  reference.Centres(a, &before);
  walk.min_clearance = reference.Clearance(a);
  double t = 0, dt = 1e-3;
  while (t < 1) {
    const double next = std::min(1.0, t + dt);
    const VecX q = a + next * (b - a);
    reference.Centres(q, &after);
    double moved = 0;
    for (size_t s = 0; s < before.size(); ++s) moved = std::max(moved, (after[s] - before[s]).norm());
    if (moved > kStep) {
      dt *= 0.5;
      continue;
    }
    walk.max_step = std::max(walk.max_step, moved);
    walk.min_clearance = std::min(walk.min_clearance, reference.Clearance(q));
    ++walk.samples;
    t = next;
    before.swap(after);
    dt *= 1.5;
  }
  return walk;
}

VecX ClampToLimits(const ArmModel& arm, VecX q) { return q.cwiseMax(arm.lower()).cwiseMin(arm.upper()); }

TEST(MotionCheckerMotionTest, AcceptedSegmentsTouchNothingAlongTheirLength) {
  for (const char* model : {"kuka_kr5_sixx_r850_barrett", "mitsubishi_pa10_pg70"}) {
    const RandomScene r = NearArmScene(model, 9, 17);
    const ArmModel arm(*r.s.view.model, r.s.view.state, "arm");
    const ArmSphereModel spheres = BuildSphereModel(*r.s.view.model, arm);
    const CollisionChecker checker(arm, spheres, CollectObstacles(*r.s.view.model, r.s.view.state, "arm"));
    const SphereReference reference(arm, spheres, r.obstacles);
    std::mt19937_64 rng(29);
    std::normal_distribution<double> normal(0.0, 1.0);
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    // A random configuration whose reference clearance is above `low` and below `high` (bounded tries).
    const auto random_with = [&](double low, double high) {
      for (int attempt = 0; attempt < 100000; ++attempt) {
        const VecX q = UniformConfiguration(arm, &rng);
        const double clearance = reference.Clearance(q);
        if (clearance > low && clearance < high) return q;
      }
      throw std::runtime_error("no configuration with clearance in the range");
    };
    const auto random_free = [&] { return random_with(1e-3, INFINITY); };
    // Kinds: 0 between two random free configurations; 1 short (0.05-0.5 rad) from a free one; 2 from a
    // configuration 0.5 mm from touching (found by bisection towards a colliding one) along the joint that moves
    // the arm away fastest (clearance gained per radian), 0.2 rad, and back; 3 from a free
    // configuration to one 0.5 mm from touching (arriving at it from a random direction).
    int accepted[4] = {0, 0, 0, 0}, tried[4] = {0, 0, 0, 0};
    double closest = INFINITY, largest_step = 0;
    for (int i = 0; i < 200; ++i) {
      const int kind = i % 4;
      VecX a = random_free(), b;
      if (kind == 0) {
        b = random_free();
      } else if (kind == 1) {
        VecX direction(arm.dof());
        for (long j = 0; j < direction.size(); ++j) direction[j] = normal(rng);
        b = ClampToLimits(arm, a + (0.05 + 0.45 * unit(rng)) * direction.normalized());
      } else {
        const VecX colliding = random_with(-INFINITY, -1e-3);
        const VecX close = AtClearance(reference, a, colliding, 5e-4);
        if (std::abs(reference.Clearance(close) - 5e-4) > 1e-5) continue;  // a jump in clearance, not a close call
        if (kind == 3) {
          b = close;
        } else {
          // d clearance / d q_j: the best joint and sign.
          int best = 0;
          double best_rate = -INFINITY;
          for (size_t j = 0; j < arm.dof(); ++j) {
            VecX h = close;
            h[j] += 1e-7;
            const double rate = (reference.Clearance(h) - 5e-4) / 1e-7;
            if (std::abs(rate) > best_rate) best_rate = std::abs(rate), best = static_cast<int>(j);
          }
          VecX h = close;
          h[best] += 1e-7;
          const double sign = reference.Clearance(h) > reference.Clearance(close) ? 1 : -1;
          a = close;
          b = close;
          b[best] += sign * 0.2;
          b = ClampToLimits(arm, b);
          if (i % 8 == 6) std::swap(a, b);  // arriving at the close configuration instead
        }
      }
      ++tried[kind];
      if (!checker.IsMotionValid(a, b)) continue;
      ++accepted[kind];
      const Walk walk = DenseWalk(reference, a, b);
      ASSERT_GT(walk.min_clearance, 0) << model << " kind " << kind << ": accepted a -> b touches\na " << a.transpose()
                                       << "\nb " << b.transpose();
      ASSERT_LE(walk.max_step, kStep);
      closest = std::min(closest, walk.min_clearance);
      largest_step = std::max(largest_step, walk.max_step);
    }
    std::printf("%s: accepted %d/%d random, %d/%d short, %d/%d leaving (or reaching) 0.5 mm from touching along the "
                "best joint, %d/%d reaching it from a random direction; closest %.3g m, step <= %.3g m\n",
                model, accepted[0], tried[0], accepted[1], tried[1], accepted[2], tried[2], accepted[3], tried[3],
                closest, largest_step);
    EXPECT_GT(accepted[0] + accepted[1], 20) << model;
    // Leaving a close call is accepted only when the arm leaves at more than about half the travel bound's rate
    // (the bound is loose for most joints); some of these do. The refinement itself: the next test.
    EXPECT_GT(accepted[2], 0) << model << ": segments ending near an obstacle are refined, not refused";
    EXPECT_LT(closest, 1e-3) << model << ": the accepted segments came close to something";
  }
}

// The KR 5 turning about its base axis, the ball 0.8 mm behind its fastest sphere.
struct NearMiss {
  ArmScene probe = MakeArmScene("kuka_kr5_sixx_r850_barrett");
  ArmModel probe_arm{*probe.view.model, probe.view.state, "arm"};
  ArmSphereModel spheres = BuildSphereModel(*probe.view.model, probe_arm);
  VecX q0;
  Obstacles ball;  // one ball "ball"
  NearMiss(double gap, double radius) {
    const Obstacles none;
    const SphereReference free_space(probe_arm, spheres, none);
    q0 = VecX::Zero(probe_arm.dof());
    q0 << 0.2, 0.5, 0.3, 0.4, 0.9, -0.3;  // reaching forward and down, clear of itself
    // The fastest sphere under joint 1 and its direction of motion.
    std::vector<Vec3> now, later;
    VecX nudged = q0;
    nudged[0] += 1e-6;
    free_space.Centres(q0, &now);
    free_space.Centres(nudged, &later);
    size_t fastest = 0;
    for (size_t s = 0; s < now.size(); ++s) {
      if ((later[s] - now[s]).norm() > (later[fastest] - now[fastest]).norm()) fastest = s;
    }
    const Vec3 u = (later[fastest] - now[fastest]).normalized();
    double sphere_radius = 0;
    for (size_t l = 0, s = 0; l < spheres.links.size(); ++l) {
      for (size_t i = 0; i < spheres.links[l].centres.size(); ++i, ++s) {
        if (s == fastest) sphere_radius = spheres.links[l].radii[i];
      }
    }
    ball.body_ids = {"ball"};
    double offset = sphere_radius + radius + gap;
    const SphereReference reference(probe_arm, spheres, ball);
    for (int i = 0; i < 20; ++i) {  // another sphere may be nearer the ball than the fastest: close the gap
      ball.balls = {{now[fastest] - offset * u, radius, 0}};
      offset += gap - reference.Clearance(q0);
    }
    ball.balls = {{now[fastest] - offset * u, radius, 0}};
  }
};

TEST(MotionCheckerMotionTest, EndWithinAMillimetreOfAnObstacleIsRefinedWhenMovingAway) {
  const NearMiss near(8e-4, 0.04);
  const ArmScene s = SceneWith("kuka_kr5_sixx_r850_barrett", near.ball);
  const ArmModel arm(*s.view.model, s.view.state, "arm");
  const CollisionChecker checker(arm, near.spheres, CollectObstacles(*s.view.model, s.view.state, "arm"));
  const SphereReference reference(arm, near.spheres, near.ball);
  ASSERT_NEAR(reference.Clearance(near.q0), 8e-4, 1e-9);
  ASSERT_TRUE(checker.IsValid(near.q0)) << checker.Explain(near.q0);
  for (const double turn : {0.5, 0.004}) {  // many checks; and a segment shorter than the resolution (one interval)
    VecX away = near.q0;
    away[0] += turn;
    // The end is nearer the ball than half of what its spheres move over the segment, and than a quarter of the
    // resolution: checks at the ends alone, inflated to cover the motion between them, would refuse it; the
    // checker has to subdivide next to the end.
    std::vector<Vec3> from, to;
    reference.Centres(near.q0, &from);
    reference.Centres(away, &to);
    double moved = 0;
    for (size_t k = 0; k < from.size(); ++k) moved = std::max(moved, (to[k] - from[k]).norm());
    ASSERT_LT(8e-4, 0.5 * moved) << "turn " << turn;
    ASSERT_LT(8e-4, 0.25 * checker.resolution());
    const Walk walk = DenseWalk(reference, near.q0, away);
    ASSERT_GE(walk.min_clearance, 8e-4 - 1e-9) << "the motion moves away from the ball";
    EXPECT_TRUE(checker.IsMotionValid(near.q0, away)) << "turn " << turn;
    EXPECT_TRUE(checker.IsMotionValid(away, near.q0)) << "turn " << turn;
    // Turning the other way runs into the ball.
    VecX into = near.q0;
    into[0] -= turn;
    if (turn > 0.01) {
      ASSERT_LT(DenseWalk(reference, near.q0, into).min_clearance, 0);
      EXPECT_FALSE(checker.IsMotionValid(near.q0, into));
      EXPECT_FALSE(checker.IsMotionValid(into, near.q0));
    }
  }
}

TEST(MotionCheckerMotionTest, ThinPlateBetweenTwoFreeEndsIsCaught) {
  // A 2 mm plate across the path of the fastest sphere, half way along a 0.3 rad turn of joint 1.
  const NearMiss geometry(0.0, 0.01);  // only for q0 and the sphere model
  const Obstacles none;
  const SphereReference free_space(geometry.probe_arm, geometry.spheres, none);
  VecX end = geometry.q0;
  end[0] += 0.3;
  VecX mid = geometry.q0;
  mid[0] += 0.15;
  VecX nudged = mid;
  nudged[0] += 1e-6;
  std::vector<Vec3> at, later;
  free_space.Centres(mid, &at);
  free_space.Centres(nudged, &later);
  size_t fastest = 0;
  for (size_t s = 0; s < at.size(); ++s) {
    if ((later[s] - at[s]).norm() > (later[fastest] - at[fastest]).norm()) fastest = s;
  }
  const Vec3 u = (later[fastest] - at[fastest]).normalized();
  Obstacles plate;
  plate.body_ids = {"plate"};
  // The plate's thin axis (local x) along the motion.
  Mat3 rotation;
  rotation.col(0) = u;
  rotation.col(1) = u.unitOrthogonal();
  rotation.col(2) = u.cross(rotation.col(1));
  plate.boxes = {{rotation, at[fastest], Vec3(0.001, 0.05, 0.05), 0}};
  const ArmScene s = SceneWith("kuka_kr5_sixx_r850_barrett", plate);
  const ArmModel arm(*s.view.model, s.view.state, "arm");
  const CollisionChecker checker(arm, geometry.spheres, CollectObstacles(*s.view.model, s.view.state, "arm"));
  const SphereReference reference(arm, geometry.spheres, plate);
  ASSERT_GT(reference.Clearance(geometry.q0), 0);
  ASSERT_GT(reference.Clearance(end), 0);
  ASSERT_LT(reference.Clearance(mid), 0);
  EXPECT_TRUE(checker.IsValid(geometry.q0));
  EXPECT_TRUE(checker.IsValid(end));
  EXPECT_FALSE(checker.IsMotionValid(geometry.q0, end));
  EXPECT_FALSE(checker.IsMotionValid(end, geometry.q0));
}

TEST(MotionCheckerMotionTest, AMeshInThePathIsCaughtWhenItIsTheOnlyObstacle) {
  // A mesh ball 4 cm across on the fastest sphere's path, half way along a 0.3 rad turn of joint 1, and nothing
  // else: the primitives' tests place no sphere, so the mesh pass has to have every sphere placed for it.
  const NearMiss geometry(0.0, 0.01);  // only for q0 and the sphere model
  const Obstacles none;
  const SphereReference free_space(geometry.probe_arm, geometry.spheres, none);
  VecX end = geometry.q0, mid = geometry.q0, away = geometry.q0;
  end[0] += 0.3;
  mid[0] += 0.15;
  away[0] -= 0.3;
  std::vector<Vec3> at;
  free_space.Centres(mid, &at);
  size_t fastest = 0;
  {
    VecX nudged = mid;
    nudged[0] += 1e-6;
    std::vector<Vec3> later;
    free_space.Centres(nudged, &later);
    for (size_t k = 0; k < at.size(); ++k) {
      if ((later[k] - at[k]).norm() > (later[fastest] - at[fastest]).norm()) fastest = k;
    }
  }
  const ArmScene s = MakeArmScene("kuka_kr5_sixx_r850_barrett", Pose{}, [&](Scene* scene) {
    AddStatic(scene, "melon", MeshBall(0.02), {at[fastest], Quat::Identity()});
  });
  const ArmModel arm(*s.view.model, s.view.state, "arm");
  // The configurations checked one by one on a checker of their own: the motion checks below start from a
  // checker that has placed no sphere yet.
  const CollisionChecker probe(arm, geometry.spheres, CollectObstacles(*s.view.model, s.view.state, "arm"));
  ASSERT_TRUE(probe.IsValid(geometry.q0));
  ASSERT_TRUE(probe.IsValid(end));
  ASSERT_TRUE(probe.IsValid(away));
  ASSERT_FALSE(probe.IsValid(mid)) << "the ball sits on the fastest sphere's centre half way";
  for (int k = 0; k <= 300; ++k) ASSERT_TRUE(probe.IsValid(geometry.q0 + (k / 300.0) * (away - geometry.q0)));
  const CollisionChecker checker(arm, geometry.spheres, CollectObstacles(*s.view.model, s.view.state, "arm"));
  EXPECT_FALSE(checker.IsMotionValid(geometry.q0, end));
  EXPECT_FALSE(checker.IsMotionValid(end, geometry.q0));
  EXPECT_TRUE(checker.IsMotionValid(geometry.q0, away)) << "turning the other way meets nothing";
}

}  // namespace
}  // namespace graspsim::motion
