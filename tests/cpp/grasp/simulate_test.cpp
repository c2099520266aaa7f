// The closing simulation on objects with exact shapes: grasps that hold, no penetration beyond the stated
// bound at any reported grasp, obstacles respected, and the same seed giving the same grasp set.
#include <chrono>
#include <cmath>
#include <cstdio>
#include <numbers>

#include <gtest/gtest.h>

#include "grasp/grasp_fixtures.h"
#include "grasp/planner.h"

namespace graspsim::grasp {
namespace {

using testing::ToMesh;

// The bound of simulate.h: contact tolerance + half the sample spacing, plus the sphere's and cylinder's chord
// error (0.1 mm, their tessellation is inscribed) and the closing chords' sagitta (0.1 mm).
double PenetrationBound(const ClosingParams& p) { return p.contact_tolerance + p.sample_spacing / 2 + 2e-4; }

std::vector<Vec3> SphereSurface(double r) {
  std::vector<Vec3> out;
  const int n = 20000;
  for (int i = 0; i < n; ++i) {
    const double z = 1 - 2 * (i + 0.5) / n, s = std::sqrt(1 - z * z), a = i * std::numbers::pi * (3 - std::sqrt(5.0));
    out.push_back(r * Vec3(s * std::cos(a), s * std::sin(a), z));
  }
  return out;
}

TEST(GraspSimulateTest, Pg70TopGraspOnASphereTouchesWithBothJaws) {
  const double r = 0.025;
  GraspPlanner planner("schunk_pg70", ToMesh(collision::SphereMesh(r)), {}, ClosingParams());
  Candidate c;
  c.approach = Vec3(0, 0, -1);  // from above
  c.target = Vec3(0, 0, r);
  c.reference = Vec3::UnitX();
  c.standoff = 0.0;
  PlannedGrasp grasp;
  ASSERT_EQ(planner.Evaluate(c, &grasp), Outcome::kGrasp);
  // The palm stops on the sphere's top (the jaws straddle it: 70 mm open, 50 mm sphere); the jaw tips reach
  // 60 mm below the palm's face... the sphere's top touches the housing, the jaws close on the sphere's sides.
  bool left = false, right = false;
  for (const GraspContact& contact : grasp.contacts) {
    EXPECT_NEAR(contact.point.norm(), r, 2e-4);
    EXPECT_GT(contact.normal.dot(-contact.point.normalized()), 0.99);  // pushing toward the centre
    const std::string& link = planner.hand().links()[contact.link].name;
    left = left || link == "finger_left";
    right = right || link == "finger_right";
  }
  EXPECT_TRUE(left && right);
  const double depth = testing::MaxPenetration(
      planner, grasp, [&](const Vec3& p) { return p.norm() - r; }, SphereSurface(r));
  EXPECT_LE(depth, PenetrationBound(ClosingParams()));
}

TEST(GraspSimulateTest, PlannedGraspsDoNotPenetrateTheObject) {
  struct Case {
    const char* hand;
    std::shared_ptr<const TriangleMesh> mesh;
    std::function<double(const Vec3&)> distance;
    std::vector<Vec3> surface;
  };
  const double r = 0.03;
  const Vec3 half(0.025, 0.02, 0.04);
  std::vector<Vec3> box_surface = testing::BoxSurface(LinkBox{Vec3::Zero(), Mat3::Identity(), half}, 1e-3);
  const std::vector<Case> cases = {
      {"schunk_pg70", ToMesh(collision::SphereMesh(r)), [&](const Vec3& p) { return p.norm() - r; }, SphereSurface(r)},
      {"schunk_pg70", ToMesh(collision::BoxMesh(half)), [&](const Vec3& p) { return testing::BoxDistance(p, half); },
       box_surface},
      {"barrett_bh8_282", ToMesh(collision::SphereMesh(0.04)), [](const Vec3& p) { return p.norm() - 0.04; },
       SphereSurface(0.04)},
      {"schunk_sdh2", ToMesh(collision::BoxMesh(half)), [&](const Vec3& p) { return testing::BoxDistance(p, half); },
       box_surface},
  };
  for (const Case& test : cases) {
    ClosingParams params;
    GraspPlanner planner(test.hand, test.mesh, {}, params);
    CandidateParams cp;
    cp.spacing = 0.02;
    cp.max_candidates = 400;
    cp.preshapes.clear();
    for (uint32_t p = 0; p < planner.hand().preshape_names().size(); ++p) cp.preshapes.push_back(p);
    const auto start = std::chrono::steady_clock::now();
    const std::vector<Candidate> candidates = planner.Candidates(cp);
    const std::optional<GraspSet> set = planner.Plan(candidates, 0, 0, [](size_t, size_t) { return true; });
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    ASSERT_TRUE(set);
    std::printf("%s: %zu candidates, %llu simulated, %llu missed, %llu force closure, %.0f candidates/s scored, %.1f s in all\n",
                test.hand, candidates.size(), static_cast<unsigned long long>(set->simulated),
                static_cast<unsigned long long>(set->missed), static_cast<unsigned long long>(set->force_closure),
                candidates.size() / set->seconds, seconds);
    EXPECT_GT(set->force_closure, 0u) << test.hand;
    double deepest = 0;
    for (const PlannedGrasp& grasp : set->grasps) {
      deepest = std::max(deepest, testing::MaxPenetration(planner, grasp, test.distance, test.surface));
    }
    EXPECT_LE(deepest, PenetrationBound(params)) << test.hand;
  }
}

}  // namespace
}  // namespace graspsim::grasp
