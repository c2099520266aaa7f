// Ferrari-Canny quality: hulls with analytic answers, grasps with known outcomes, and qhull against an
// independent brute-force float64 reference (wrench_reference.h) within 1e-9 relative.
#include <cmath>
#include <numbers>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "grasp/quality.h"
#include "grasp/wrench_reference.h"

namespace graspsim::grasp {
namespace {

// The cross-polytope {±k e_i}: every facet is at distance k/√6 from the centre; volume 2^6 k^6 / 6!.
TEST(GraspQualityTest, CrossPolytopeHasAnalyticEpsilonAndVolume) {
  for (double k : {0.5, 1.0, 3.0}) {
    std::vector<Wrench> w;
    for (int i = 0; i < 6; ++i) {
      for (double sign : {-1.0, 1.0}) {
        Wrench e{};
        e[i] = sign * k;
        w.push_back(e);
      }
    }
    const Quality q = HullQuality(w);
    EXPECT_TRUE(q.force_closure);
    EXPECT_NEAR(q.epsilon, k / std::sqrt(6.0), 1e-12 * k);
    EXPECT_NEAR(q.volume, std::pow(2 * k, 6) / 720, 1e-9 * std::pow(2 * k, 6) / 720);
  }
}

// The hypercube [-1, 1]^6 (64 corners): ε = 1, volume 2^6.
TEST(GraspQualityTest, HypercubeHasEpsilonOneAndVolume64) {
  std::vector<Wrench> w;
  for (int mask = 0; mask < 64; ++mask) {
    Wrench e;
    for (int i = 0; i < 6; ++i) e[i] = (mask >> i) & 1 ? 1.0 : -1.0;
    w.push_back(e);
  }
  const Quality q = HullQuality(w);
  EXPECT_TRUE(q.force_closure);
  EXPECT_NEAR(q.epsilon, 1.0, 1e-12);
  EXPECT_NEAR(q.volume, 64.0, 1e-9);
}

// A shifted hull that does not contain the origin is not force closure.
TEST(GraspQualityTest, OriginOutsideIsNotForceClosure) {
  std::vector<Wrench> w;
  for (int mask = 0; mask < 64; ++mask) {
    Wrench e;
    for (int i = 0; i < 6; ++i) e[i] = ((mask >> i) & 1 ? 1.0 : -1.0) + (i == 2 ? 1.5 : 0.0);
    w.push_back(e);
  }
  const Quality q = HullQuality(w);
  EXPECT_FALSE(q.force_closure);
  EXPECT_EQ(q.epsilon, 0);
  EXPECT_NEAR(q.volume, 64.0, 1e-9);  // the hull itself is the same cube
}

// One contact's primitive wrenches, by hand: contact at (r, 0, 0) of a sphere of radius r pushing along -x.
TEST(GraspQualityTest, ContactWrenchesMatchTheDefinition) {
  const double r = 0.05, mu = 0.4;
  const GraspContact c{Vec3(r, 0, 0), Vec3(-1, 0, 0), 0};
  std::vector<Wrench> w;
  ContactWrenches(&c, 1, Vec3::Zero(), r, mu, 8, &w);
  ASSERT_EQ(w.size(), 8u);
  for (const Wrench& e : w) {
    const Vec3 f(e[0], e[1], e[2]), tau(e[3], e[4], e[5]);
    EXPECT_NEAR(f.x(), -1, 1e-15);                                   // unit normal component
    EXPECT_NEAR(std::hypot(f.y(), f.z()), mu, 1e-15);                // on the cone's rim
    const Vec3 expected = Vec3(1, 0, 0).cross(f);                    // (p - c) / λ × f with |p - c| = λ
    EXPECT_NEAR((tau - expected).norm(), 0, 1e-15);
  }
  ContactWrenches(&c, 1, Vec3::Zero(), r, 0.0, 8, &w);  // frictionless: the normal only
  ASSERT_EQ(w.size(), 1u);
}

// Two antipodal frictional contacts on a sphere: nothing resists torsion about the line through them.
TEST(GraspQualityTest, AntipodalContactsOnASphereAreNotForceClosure) {
  for (double mu : {0.2, 0.4, 1.0}) {
    const GraspContact c[2] = {{Vec3(0.03, 0, 0), Vec3(-1, 0, 0), 0}, {Vec3(-0.03, 0, 0), Vec3(1, 0, 0), 1}};
    std::vector<Wrench> w;
    const Quality q = GraspQuality(c, 2, Vec3::Zero(), 0.03, mu, 8, &w);
    EXPECT_FALSE(q.force_closure) << mu;
    EXPECT_EQ(q.epsilon, 0);
  }
}

// Three frictional contacts 120° apart on a sphere's equator hold it (ε > 0), and ε grows with μ.
TEST(GraspQualityTest, ThreeContactsOnASphereGrowWithFriction) {
  double previous = 0;
  for (double mu : {0.2, 0.4, 0.8}) {
    std::vector<GraspContact> c;
    for (int k = 0; k < 3; ++k) {
      const double a = 2 * std::numbers::pi * k / 3;
      const Vec3 p(std::cos(a), std::sin(a), 0);
      c.push_back({0.04 * p, -p, k});
    }
    std::vector<Wrench> w;
    const Quality q = GraspQuality(c.data(), c.size(), Vec3::Zero(), 0.04, mu, 8, &w);
    EXPECT_TRUE(q.force_closure) << mu;
    EXPECT_GT(q.epsilon, previous);
    EXPECT_NEAR(q.epsilon, testing::ReferenceEpsilon(w), 1e-9 * q.epsilon);
    previous = q.epsilon;
  }
}

// Frictionless two-contact grasps are never force closure, wherever the contacts are.
TEST(GraspQualityTest, FrictionlessTwoFingerGraspsAreNeverForceClosure) {
  std::mt19937_64 random(7);
  std::normal_distribution<double> normal;
  for (int trial = 0; trial < 200; ++trial) {
    GraspContact c[2];
    for (auto& contact : c) {
      const Vec3 p = Vec3(normal(random), normal(random), normal(random)).normalized() * 0.05;
      contact = {p, -p.normalized(), 0};
    }
    std::vector<Wrench> w;
    EXPECT_FALSE(GraspQuality(c, 2, Vec3::Zero(), 0.05, 0.0, 8, &w).force_closure);
  }
}

// Box grasps: two flat jaws on opposite faces of a 6 x 4 x 4 cm box (a PG70 grasp), each touching along a
// line (two contacts): force closure, since the friction couple across each line resists torsion; ε as the
// reference computes it, for two line lengths. Without friction the same grasp is not force closure.
TEST(GraspQualityTest, BoxJawGraspsMatchTheReference) {
  const Vec3 half(0.03, 0.02, 0.02);
  for (double patch : {0.01, 0.005}) {
    std::vector<GraspContact> c;
    for (double side : {-1.0, 1.0}) {
      for (double dz : {-patch, patch}) c.push_back({Vec3(0, side * half.y(), dz), Vec3(0, -side, 0), 0});
    }
    std::vector<Wrench> w;
    const Quality q = GraspQuality(c.data(), c.size(), Vec3::Zero(), half.norm(), 0.4, 8, &w);
    EXPECT_TRUE(q.force_closure);
    EXPECT_NEAR(q.epsilon, testing::ReferenceEpsilon(w), 1e-9 * q.epsilon);
    EXPECT_FALSE(GraspQuality(c.data(), c.size(), Vec3::Zero(), half.norm(), 0.0, 8, &w).force_closure);
  }
}

// Random grasps of 3 and 4 contacts on spheres and boxes: qhull's ε equals the brute-force reference.
TEST(GraspQualityTest, EpsilonMatchesBruteForceReference) {
  std::mt19937_64 random(11);
  std::uniform_real_distribution<double> uniform(-1, 1);
  int force_closure = 0;
  for (int trial = 0; trial < 12; ++trial) {
    const int count = 3 + trial % 2;
    const int edges = count == 3 ? 8 : 6;  // 24 wrenches either way: C(24, 6) subsets for the reference
    std::vector<GraspContact> c;
    for (int k = 0; k < count; ++k) {
      Vec3 p(uniform(random), uniform(random), uniform(random));
      Vec3 n;
      if (trial % 3 == 0) {  // a box face: the largest coordinate pushed to the surface
        int axis;
        p.cwiseAbs().maxCoeff(&axis);
        p[axis] = p[axis] > 0 ? 1 : -1;
        n = Vec3::Zero();
        n[axis] = -p[axis];
      } else {
        p.normalize();
        n = -p;
      }
      c.push_back({0.05 * p, n, k});
    }
    const double mu = 0.3 + 0.5 * (uniform(random) + 1) / 2;
    std::vector<Wrench> w;
    const Quality q = GraspQuality(c.data(), c.size(), Vec3::Zero(), 0.05 * std::sqrt(3.0), mu, edges, &w);
    const double reference = testing::ReferenceEpsilon(w);
    EXPECT_EQ(q.force_closure, reference > 0) << trial;
    EXPECT_NEAR(q.epsilon, reference, 1e-9 * std::max(reference, 1e-300)) << trial;
    force_closure += q.force_closure;
  }
  EXPECT_GT(force_closure, 3);  // the comparison covered real hulls, not only zeros
}

// The nearest-facet search (what planning uses) and qhull's whole hull give the same ε, on grasps of up to
// nine contacts where the brute-force reference would be too slow.
TEST(GraspQualityTest, NearestFacetMatchesQhull) {
  std::mt19937_64 random(5);
  std::uniform_real_distribution<double> uniform(-1, 1);
  int force_closure = 0;
  for (int trial = 0; trial < 60; ++trial) {
    std::vector<GraspContact> c;
    const int count = 3 + trial % 7;
    for (int k = 0; k < count; ++k) {
      const Vec3 p = Vec3(uniform(random), uniform(random), uniform(random)).normalized();
      c.push_back({0.04 * p, -p, k});
    }
    std::vector<Wrench> w;
    ContactWrenches(c.data(), c.size(), Vec3::Zero(), 0.04, 0.5, 8, &w);
    const Quality fast = FastQuality(w), hull = HullQuality(w);
    EXPECT_EQ(fast.force_closure, hull.force_closure) << trial;
    EXPECT_NEAR(fast.epsilon, hull.epsilon, 1e-9 * std::max(hull.epsilon, 1e-300)) << trial;
    force_closure += hull.force_closure;
  }
  EXPECT_GT(force_closure, 20);
}

}  // namespace
}  // namespace graspsim::grasp
