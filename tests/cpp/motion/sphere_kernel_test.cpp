// The SIMD sphere kernel against a double-precision reference written here (sphere_reference.h): the checker's
// IsValid agrees with the exact sphere test wherever the arm is more than 0.1 mm from touching (random
// configurations, and configurations bisected to within 0.3 mm of touching); kernel::CollidingLanes answers each
// lane as the reference does with that lane's own inflation (scaled per link and per self pair when the model says
// so) and places the spheres where the reference does; the
// AVX2 and the portable build give the same masks on the same inputs; and the 0.02 mm float margin is where the
// header says it is.
#include <cstdio>
#include <random>

#include <gtest/gtest.h>

#include "motion/collision_checker.h"
#include "motion/sphere_kernel.h"
#include "sphere_reference.h"

namespace graspsim::motion {
namespace {

using namespace motion_test;
namespace k = kernel;

constexpr double kBand = 1e-4;  // m: within this of touching, float and double may disagree

const char* const kArms[] = {"kuka_kr5_sixx_r850_barrett", "mitsubishi_pa10_pg70"};

TEST(MotionSphereKernelTest, IsValidAgreesWithDoublePrecisionSpheres) {
  for (const char* model : kArms) {
    const RandomScene r = NearArmScene(model, 9, 41);
    const ArmModel arm(*r.s.view.model, r.s.view.state, "arm");
    const ArmSphereModel spheres = BuildSphereModel(*r.s.view.model, arm);
    const CollisionChecker checker(arm, spheres, CollectObstacles(*r.s.view.model, r.s.view.state, "arm"));
    const SphereReference reference(arm, spheres, r.obstacles);
    std::mt19937_64 rng(3);
    std::vector<VecX> free, colliding;
    int near = 0;
    for (int i = 0; i < 4000; ++i) {
      const VecX q = UniformConfiguration(arm, &rng);
      const double clearance = reference.Clearance(q);
      if (std::abs(clearance) < kBand) {
        ++near;
        continue;
      }
      ASSERT_EQ(checker.IsValid(q), clearance > 0) << model << " clearance " << clearance << " q " << q.transpose();
      (clearance > 0 ? free : colliding).push_back(q);
    }
    ASSERT_GT(free.size(), 200u) << model;
    ASSERT_GT(colliding.size(), 200u) << model;
    // Close calls: configurations 0.3 mm either side of touching (obstacle or self), found by bisection.
    int close = 0;
    for (size_t i = 0; i < 150; ++i) {
      const VecX& a = free[i];
      const VecX& b = colliding[i];
      for (const double target : {3e-4, -3e-4, 1.5e-4, -1.5e-4}) {
        const VecX q = AtClearance(reference, a, b, target);
        const double clearance = reference.Clearance(q);
        if (std::abs(clearance - target) > 5e-5) continue;  // the clearance jumps here (a limit or a new pair)
        ++close;
        EXPECT_EQ(checker.IsValid(q), clearance > 0) << model << " clearance " << clearance << " q " << q.transpose();
      }
    }
    EXPECT_GT(close, 400) << model;
    std::printf("%s: %zu free, %zu colliding, %d within 0.1 mm skipped, %d close calls\n", model, free.size(),
                colliding.size(), near, close);
  }
}

// Random lanes of q (joint angles beyond the limits too: the kernel's sine and cosine reduce any angle) with
// random per-lane inflation; the reference per lane with that inflation.
struct LaneCase {
  std::vector<float> q;        // dof rows of kLanes
  float inflate[k::kLanes];
  std::vector<VecX> configurations;  // the same q in double (from the floats)
};

LaneCase RandomLanes(const ArmModel& arm, std::mt19937_64* rng) {
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  LaneCase c;
  c.q.resize(arm.dof() * k::kLanes);
  for (int lane = 0; lane < k::kLanes; ++lane) {
    VecX q = UniformConfiguration(arm, rng);
    if (lane == 7) {  // far outside the limits: revolute joints anywhere in +-(2 pi + 1)
      for (size_t j = 0; j < arm.dof(); ++j) {
        if (arm.dof_types()[j] != JointType::kPrismatic) q[j] = (2 * unit(*rng) - 1) * (2 * EIGEN_PI + 1);
      }
    }
    for (size_t j = 0; j < arm.dof(); ++j) {
      c.q[j * k::kLanes + lane] = static_cast<float>(q[j]);
      q[j] = c.q[j * k::kLanes + lane];
    }
    c.configurations.push_back(q);
    c.inflate[lane] = lane % 4 == 0 ? 0.0f : static_cast<float>(0.03 * unit(*rng));
  }
  return c;
}

TEST(MotionSphereKernelTest, EachLaneAnswersWithItsOwnInflationAndPlacesSpheresExactly) {
  for (const char* model : {"kuka_kr5_sixx_r850_barrett", "mitsubishi_pa10_pg70", "schunk_pg70_on_z_axis"}) {
    const RandomScene r = NearArmScene(model, 9, 43);
    const ArmModel arm(*r.s.view.model, r.s.view.state, "arm");
    const ArmSphereModel spheres = BuildSphereModel(*r.s.view.model, arm);
    const SphereReference reference(arm, spheres, r.obstacles);
    KernelInput input(arm, spheres, r.obstacles);
    std::mt19937_64 rng(5);
    // Per-link and per-pair scales of the lane's inflation (Model::link_inflation / pair_inflation): random ones
    // for the odd batches, none (1 per link, 2 per pair) for the even ones.
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    SphereReference::Scales scales;
    std::vector<float> link_scale, pair_scale;
    for (size_t l = 0; l < arm.links().size(); ++l) {
      scales.link.push_back(static_cast<float>(3 * unit(rng)));
      link_scale.push_back(static_cast<float>(scales.link.back()));
    }
    for (size_t p = 0; p < spheres.self_pairs.size(); ++p) {
      scales.pair.push_back(static_cast<float>(4 * unit(rng)));
      pair_scale.push_back(static_cast<float>(scales.pair.back()));
    }
    int lanes_hit = 0, lanes_free = 0, near = 0;
    double worst_centre = 0;
    std::vector<Vec3> centres;
    for (int batch = 0; batch < 600; ++batch) {
      const LaneCase c = RandomLanes(arm, &rng);
      const bool scaled = batch % 2 == 1;
      input.model.link_inflation = scaled ? link_scale.data() : nullptr;
      input.model.pair_inflation = scaled ? pair_scale.data() : nullptr;
      // Spheres placed only where a test reads them in the batches of one in three, the masks the same; the
      // obstacles' broad phase off in one batch in four.
      input.model.place_every_sphere = batch % 3 != 0;
      input.model.obstacle_bounds = batch % 4 == 3 ? nullptr : input.obstacle_bounds.data();
      const uint32_t all = k::CollidingLanes(input.model, c.q.data(), c.inflate, input.scratch.data(), k::kRunToEnd);
      // With some lane free at the end, every sphere's centre is in scratch when asked for.
      const bool centres_placed = input.model.place_every_sphere && all != 0xffu;
      const float* placed = k::SphereCentres(input.model, input.scratch.data());
      uint32_t expected = 0, unsure = 0;
      for (int lane = 0; lane < k::kLanes; ++lane) {
        const double clearance =
            reference.Clearance(c.configurations[lane], c.inflate[lane], nullptr, scaled ? &scales : nullptr);
        if (std::abs(clearance) < kBand) unsure |= 1u << lane;
        if (clearance < 0) expected |= 1u << lane;
        reference.Centres(c.configurations[lane], &centres);
        for (size_t s = 0; centres_placed && s < centres.size(); ++s) {
          const Vec3 kernel_centre(placed[(3 * s) * k::kLanes + lane], placed[(3 * s + 1) * k::kLanes + lane],
                                   placed[(3 * s + 2) * k::kLanes + lane]);
          worst_centre = std::max(worst_centre, (kernel_centre - centres[s]).norm());
        }
      }
      ASSERT_EQ(all & ~unsure, expected & ~unsure) << model << " batch " << batch;
      near += __builtin_popcount(unsure);
      lanes_hit += __builtin_popcount(expected & ~unsure);
      lanes_free += __builtin_popcount(~expected & ~unsure & 0xffu);
      // Stopping at the first hit: some lane when any, and only lanes that collide.
      const uint32_t first = k::CollidingLanes(input.model, c.q.data(), c.inflate, input.scratch.data(), k::kStopAtFirst);
      EXPECT_EQ(first != 0, all != 0) << model << " batch " << batch;
      EXPECT_EQ(first & ~all, 0u) << model << " batch " << batch;
      // Stopping at one lane: that lane's answer is right, and when it is free every lane's is.
      const uint32_t one = 1u << (batch % k::kLanes);
      const uint32_t stopped = k::CollidingLanes(input.model, c.q.data(), c.inflate, input.scratch.data(), k::StopLanes{one});
      EXPECT_EQ(stopped & one, all & one) << model << " batch " << batch;
      EXPECT_EQ(stopped & ~all, 0u) << model << " batch " << batch;
      if (!(all & one)) {
        EXPECT_EQ(stopped, all) << model << " batch " << batch;
      }
    }
    // Float placement: well inside the 0.02 mm margin the radii carry.
    EXPECT_LT(worst_centre, 5e-6) << model;
    EXPECT_GT(lanes_hit, 150) << model;
    EXPECT_GT(lanes_free, 150) << model;
    std::printf("%s: %d lanes colliding, %d free, %d within 0.1 mm; centres within %.2g m\n", model, lanes_hit,
                lanes_free, near, worst_centre);
  }
}

TEST(MotionSphereKernelTest, Avx2AndPortableBuildsGiveTheSameMasks) {
#if !defined(__x86_64__)
  GTEST_SKIP() << "one build only on this architecture";
#else
  __builtin_cpu_init();
  if (!__builtin_cpu_supports("avx2") || !__builtin_cpu_supports("fma")) {
    GTEST_SKIP() << "this CPU has no AVX2 + FMA: the AVX2 build cannot run here";
  }
  for (const char* model : {"kuka_kr5_sixx_r850_barrett", "mitsubishi_pa10_pg70", "schunk_pg70_on_z_axis"}) {
    const RandomScene r = NearArmScene(model, 9, 47);
    const ArmModel arm(*r.s.view.model, r.s.view.state, "arm");
    const ArmSphereModel spheres = BuildSphereModel(*r.s.view.model, arm);
    const SphereReference reference(arm, spheres, r.obstacles);
    KernelInput input(arm, spheres, r.obstacles);
    std::vector<float> scratch_generic(input.scratch.size());
    std::mt19937_64 rng(9);
    int differing = 0, hits = 0;
    double worst_centre = 0;
    for (int batch = 0; batch < 800; ++batch) {
      const LaneCase c = RandomLanes(arm, &rng);
      const uint32_t fast = k::avx2::CollidingLanes(input.model, c.q.data(), c.inflate, input.scratch.data(), k::kRunToEnd);
      const uint32_t portable =
          k::generic::CollidingLanes(input.model, c.q.data(), c.inflate, scratch_generic.data(), k::kRunToEnd);
      hits += __builtin_popcount(fast);
      if (fast != portable) {
        // FMA rounds differently from multiply-then-add: a lane may flip only within float error of touching.
        for (int lane = 0; lane < k::kLanes; ++lane) {
          if (((fast ^ portable) >> lane) & 1u) {
            ++differing;
            EXPECT_LT(std::abs(reference.Clearance(c.configurations[lane], c.inflate[lane])), kBand)
                << model << " batch " << batch << " lane " << lane;
          }
        }
      }
      // Both placed every sphere unless a build's lanes all collided (the portable one runs 4 lanes at a time).
      if ((fast & 0xfu) == 0xfu || (fast >> 4) == 0xfu || (portable & 0xfu) == 0xfu || (portable >> 4) == 0xfu) continue;
      const float* a = k::SphereCentres(input.model, input.scratch.data());
      const float* b = k::SphereCentres(input.model, scratch_generic.data());
      for (int64_t i = 0; i < 3LL * input.model.sphere_count * k::kLanes; ++i) {
        worst_centre = std::max(worst_centre, static_cast<double>(std::abs(a[i] - b[i])));
      }
    }
    EXPECT_GT(hits, 500) << model;
    EXPECT_LT(worst_centre, 5e-6) << model;
    std::printf("%s: %d lanes colliding, %d differing between the builds; centres within %.2g m\n", model, hits,
                differing, worst_centre);
  }
  EXPECT_STREQ(k::KernelIsa(), std::getenv("GRASPSIM_KERNEL") && std::string(std::getenv("GRASPSIM_KERNEL")) == "generic"
                                   ? "sse2"
                                   : "avx2");
#endif
}

// ClearanceLanes: per lane the largest inflation up to the cap at which the reference says "free". Never more
// (the reference is free at the kernel's clearance: the radii's float margin is on its side), and, below the cap,
// not more than 1e-3 (in inflation units) less (the reference touches at the clearance + 1e-3); negative exactly
// where CollidingLanes with no inflation hits; the AVX2 and portable builds within float error of each other; every
// sphere placed when the model asks for it.
TEST(MotionSphereKernelTest, ClearanceIsTheLargestInflationAtWhichTheReferenceIsFree) {
  for (const char* model : {"kuka_kr5_sixx_r850_barrett", "mitsubishi_pa10_pg70", "schunk_pg70_on_z_axis"}) {
    const RandomScene r = NearArmScene(model, 9, 53);
    const ArmModel arm(*r.s.view.model, r.s.view.state, "arm");
    const ArmSphereModel spheres = BuildSphereModel(*r.s.view.model, arm);
    const SphereReference reference(arm, spheres, r.obstacles);
    KernelInput input(arm, spheres, r.obstacles);
    std::vector<float> scratch_generic(input.scratch.size());
    std::mt19937_64 rng(17);
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    SphereReference::Scales scales;
    std::vector<float> link_scale, pair_scale;
    for (size_t l = 0; l < arm.links().size(); ++l) link_scale.push_back(static_cast<float>(0.2 + 2.8 * unit(rng)));
    for (size_t p = 0; p < spheres.self_pairs.size(); ++p) pair_scale.push_back(static_cast<float>(0.2 + 3.8 * unit(rng)));
    scales.link.assign(link_scale.begin(), link_scale.end());
    scales.pair.assign(pair_scale.begin(), pair_scale.end());
    int measured = 0, capped = 0, touching = 0;
    double worst_builds = 0, worst_centre = 0;
    for (int batch = 0; batch < 600; ++batch) {
      const LaneCase c = RandomLanes(arm, &rng);
      const bool scaled = batch % 2 == 1;
      input.model.link_inflation = scaled ? link_scale.data() : nullptr;
      input.model.pair_inflation = scaled ? pair_scale.data() : nullptr;
      input.model.place_every_sphere = batch % 3 != 0;
      input.model.obstacle_bounds = batch % 4 == 3 ? nullptr : input.obstacle_bounds.data();
      float cap[k::kLanes], clearance[k::kLanes], generic_clearance[k::kLanes];
      for (int lane = 0; lane < k::kLanes; ++lane) cap[lane] = lane % 4 == 0 ? 0.0f : static_cast<float>(0.1 * unit(rng));
      const uint32_t hits =
          k::ClearanceLanes(input.model, c.q.data(), cap, input.scratch.data(), clearance, k::kRunToEnd);
      // With Model::place_every_sphere (the checker's mesh pass reads them), every sphere's centre is placed (read
      // before CollidingLanes below, which places them in the same scratch itself).
      if (input.model.place_every_sphere && hits != 0xffu) {
        std::vector<Vec3> centres;
        const float* placed = k::SphereCentres(input.model, input.scratch.data());
        for (int lane = 0; lane < k::kLanes; ++lane) {
          reference.Centres(c.configurations[lane], &centres);
          for (size_t s = 0; s < centres.size(); ++s) {
            const Vec3 kernel_centre(placed[(3 * s) * k::kLanes + lane], placed[(3 * s + 1) * k::kLanes + lane],
                                     placed[(3 * s + 2) * k::kLanes + lane]);
            worst_centre = std::max(worst_centre, (kernel_centre - centres[s]).norm());
          }
        }
      }
      const float zero[k::kLanes] = {};
      EXPECT_EQ(hits, k::CollidingLanes(input.model, c.q.data(), zero, input.scratch.data(), k::kRunToEnd))
          << model << " batch " << batch;
      const uint32_t portable =
          k::generic::ClearanceLanes(input.model, c.q.data(), cap, scratch_generic.data(), generic_clearance, k::kRunToEnd);
      EXPECT_EQ(hits, portable) << model << " batch " << batch;
      for (int lane = 0; lane < k::kLanes; ++lane) {
        const SphereReference::Scales* s = scaled ? &scales : nullptr;
        const VecX& q = c.configurations[lane];
        if ((hits >> lane) & 1u) {
          EXPECT_LT(clearance[lane], 0.0f) << model << " batch " << batch << " lane " << lane;
          EXPECT_LT(reference.Clearance(q), kBand) << model << " batch " << batch << " lane " << lane;
          ++touching;
          continue;
        }
        worst_builds = std::max(worst_builds, static_cast<double>(std::abs(clearance[lane] - generic_clearance[lane])));
        ASSERT_LE(clearance[lane], cap[lane]) << model << " batch " << batch << " lane " << lane;
        EXPECT_GE(reference.Clearance(q, clearance[lane], nullptr, s), 0.0)
            << model << " batch " << batch << " lane " << lane << ": the kernel overstates the clearance";
        if (clearance[lane] < cap[lane] - 1e-3f) {
          ++measured;
          EXPECT_LT(reference.Clearance(q, clearance[lane] + 1e-3, nullptr, s), 0.0)
              << model << " batch " << batch << " lane " << lane << ": the kernel understates the clearance";
        } else {
          ++capped;
        }
      }
    }
    EXPECT_LT(worst_builds, 1e-5) << model;
    EXPECT_LT(worst_centre, 5e-6) << model;
    // Enough of each kind (the gripper on its axis collides with the scene's blocks in most random configurations).
    EXPECT_GT(measured, 100) << model;
    EXPECT_GT(capped, 40) << model;
    EXPECT_GT(touching, 150) << model;
    std::printf("%s: %d lanes measured below the cap, %d at the cap, %d touching; builds within %.2g\n", model,
                measured, capped, touching, worst_builds);
  }
}

TEST(MotionSphereKernelTest, ConfigurationsWithinTheFloatMarginAreNotValid) {
  // The header: valid means no sphere touches, radii as modelled plus 0.02 mm. 5 um from touching is refused
  // (and Explain names a pair: its double test uses the same radii); 0.1 mm away is free.
  const RandomScene r = NearArmScene("kuka_kr5_sixx_r850_barrett", 9, 41);
  const ArmModel arm(*r.s.view.model, r.s.view.state, "arm");
  const ArmSphereModel spheres = BuildSphereModel(*r.s.view.model, arm);
  const CollisionChecker checker(arm, spheres, CollectObstacles(*r.s.view.model, r.s.view.state, "arm"));
  const SphereReference reference(arm, spheres, r.obstacles);
  std::mt19937_64 rng(13);
  int tested = 0;
  for (int attempt = 0; attempt < 20000 && tested < 20; ++attempt) {
    const VecX a = UniformConfiguration(arm, &rng), b = UniformConfiguration(arm, &rng);
    if (!(reference.Clearance(a) > 0.01 && reference.Clearance(b) < -0.01)) continue;
    const VecX inside_margin = AtClearance(reference, a, b, 5e-6);
    const VecX outside_margin = AtClearance(reference, a, b, 1e-4);
    if (std::abs(reference.Clearance(inside_margin) - 5e-6) > 1e-6) continue;
    if (std::abs(reference.Clearance(outside_margin) - 1e-4) > 1e-6) continue;
    ++tested;
    EXPECT_FALSE(checker.IsValid(inside_margin)) << inside_margin.transpose();
    EXPECT_NE(checker.Explain(inside_margin), "");
    EXPECT_TRUE(checker.IsValid(outside_margin)) << outside_margin.transpose();
    EXPECT_EQ(checker.Explain(outside_margin), "");
  }
  EXPECT_EQ(tested, 20);
}

}  // namespace
}  // namespace graspsim::motion
