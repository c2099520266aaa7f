// The sphere model is conservative: every point of every link's collision geometry (the vertices of its
// tessellation and random points inside it) lies inside that link's spheres; the checker built on it never
// calls a configuration free that the exact geometry finds colliding.
#include <algorithm>
#include <random>

#include <gtest/gtest.h>

#include "collision/tessellation.h"
#include "motion/collision_checker.h"
#include "motion/exact_checker.h"
#include "motion/sphere_model.h"
#include "motion_test_scenes.h"

namespace graspsim::motion {
namespace {

using namespace motion_test;

bool InsideSpheres(const LinkSpheres& spheres, const Vec3& p) {
  for (size_t s = 0; s < spheres.centres.size(); ++s) {
    if ((p - spheres.centres[s]).norm() <= spheres.radii[s] * (1 + 1e-12)) return true;
  }
  return false;
}

// Points of the geometry in its own frame: the tessellation's vertices (every corner and rim) and random
// points of the solid.
std::vector<Vec3> PointsOf(const Geometry& g, std::mt19937_64* rng) {
  collision::LocalMesh mesh;
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::vector<Vec3> points;
  switch (g.kind) {
    case Geometry::Kind::kBox:
      mesh = collision::BoxMesh(0.5 * g.box_size);
      for (int i = 0; i < 500; ++i) points.push_back(0.5 * g.box_size.cwiseProduct(Vec3(u(*rng), u(*rng), u(*rng))));
      break;
    case Geometry::Kind::kCylinder:
      mesh = collision::CylinderMesh(g.radius, 0.5 * g.length);
      for (int i = 0; i < 500; ++i) {
        const Vec3 p(u(*rng), u(*rng), u(*rng));
        if (p.head<2>().norm() <= 1) points.push_back(Vec3(g.radius * p.x(), g.radius * p.y(), 0.5 * g.length * p.z()));
      }
      break;
    case Geometry::Kind::kSphere:
      mesh = collision::SphereMesh(g.radius);
      break;
    case Geometry::Kind::kMesh:
      for (const auto& v : g.mesh->vertices) points.push_back(v.cast<double>());
      break;
  }
  points.insert(points.end(), mesh.vertices.begin(), mesh.vertices.end());
  return points;
}

TEST(MotionSphereModelTest, EveryLinkPointLiesInsideItsSpheres) {
  std::mt19937_64 rng(7);
  for (const char* model : {"kuka_kr5_sixx_r850_barrett", "kuka_kr5_sixx_r850_sdh2", "kuka_kr5_sixx_r850_pg70",
                            "mitsubishi_pa10_barrett", "mitsubishi_pa10_sdh2", "mitsubishi_pa10_pg70"}) {
    const auto s = MakeArmScene(model);
    const ArmModel arm(*s.view.model, s.view.state, "arm");
    const ArmSphereModel spheres = BuildSphereModel(*s.view.model, arm);
    size_t checked = 0;
    for (size_t l = 0; l < arm.links().size(); ++l) {
      for (const Geometry& g : s.view.model->bodies[arm.links()[l].body].collision) {
        for (const Vec3& local : PointsOf(g, &rng)) {
          const Vec3 p = g.origin * local;  // into the link frame
          EXPECT_TRUE(InsideSpheres(spheres.links[l], p)) << model << " " << arm.links()[l].id << " " << p.transpose();
          EXPECT_LE((p - spheres.links[l].bound_centre).norm(), spheres.links[l].bound_radius + 1e-12);
          ++checked;
        }
      }
    }
    EXPECT_GT(checked, 1000u) << model;
    EXPECT_FALSE(spheres.self_pairs.empty()) << model;
  }
}

// Self pairs are chosen as MoveIt's Setup Assistant chooses them (sphere_model.h: links with geometry that move
// relative to each other, not adjacent, and neither apart nor touching in every one of 10,000 samples). This test
// replaced the one for the former rule (links three or more dofs apart; the KR 5's palm against link_3), which
// the sampling rule no longer follows: checked here against samples of its own.
TEST(MotionSphereModelTest, SelfPairsAreTheLinksThatSometimesTouch) {
  const auto s = MakeArmScene("kuka_kr5_sixx_r850_barrett");
  const ArmModel arm(*s.view.model, s.view.state, "arm");
  const ArmSphereModel spheres = BuildSphereModel(*s.view.model, arm);
  const size_t n = arm.links().size();
  const auto has_geometry = [&](size_t l) { return spheres.links[l].bound_radius >= 0; };
  std::vector<std::vector<bool>> is_pair(n, std::vector<bool>(n, false));
  for (const auto& [a, b] : spheres.self_pairs) {
    ASSERT_LT(a, b);
    is_pair[a][b] = true;
    EXPECT_TRUE(has_geometry(a) && has_geometry(b));
    EXPECT_NE(spheres.group[a], spheres.group[b]) << arm.links()[a].id << " " << arm.links()[b].id;
    int ancestor = arm.links()[b].parent;  // b's nearest ancestor with geometry is not a
    while (ancestor >= 0 && !has_geometry(ancestor)) ancestor = arm.links()[ancestor].parent;
    EXPECT_NE(ancestor, static_cast<int>(a)) << arm.links()[a].id << " " << arm.links()[b].id << " are adjacent";
  }
  // Samples of this test's own: a pair is not touching everywhere; a candidate touching in 1 % of them or more is
  // a pair (10,000 samples miss it with probability e^-100).
  std::mt19937_64 rng(77);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::vector<std::vector<int>> touching(n, std::vector<int>(n, 0));
  std::vector<Rigid> poses;
  constexpr int kSamples = 4000;
  for (int k = 0; k < kSamples; ++k) {
    VecX q(arm.dof());
    for (size_t j = 0; j < arm.dof(); ++j) q[j] = arm.lower()[j] + unit(rng) * (arm.upper()[j] - arm.lower()[j]);
    arm.LinkTransforms(q, &poses);
    for (size_t a = 0; a < n; ++a) {
      for (size_t b = a + 1; b < n; ++b) {
        if (!has_geometry(a) || !has_geometry(b) || spheres.group[a] == spheres.group[b]) continue;
        bool touch = false;
        for (size_t i = 0; i < spheres.links[a].centres.size() && !touch; ++i) {
          for (size_t j = 0; j < spheres.links[b].centres.size() && !touch; ++j) {
            touch = (poses[a] * spheres.links[a].centres[i] - poses[b] * spheres.links[b].centres[j]).norm() <
                    spheres.links[a].radii[i] + spheres.links[b].radii[j];
          }
        }
        touching[a][b] += touch;
      }
    }
  }
  int frequent = 0;
  for (size_t a = 0; a < n; ++a) {
    for (size_t b = a + 1; b < n; ++b) {
      if (is_pair[a][b]) {
        EXPECT_LT(touching[a][b], kSamples) << arm.links()[a].id << " " << arm.links()[b].id;
      }
      int ancestor = arm.links()[b].parent;
      while (ancestor >= 0 && !has_geometry(ancestor)) ancestor = arm.links()[ancestor].parent;
      if (ancestor == static_cast<int>(a) || touching[a][b] < kSamples / 100 || touching[a][b] == kSamples) continue;
      ++frequent;
      EXPECT_TRUE(is_pair[a][b]) << arm.links()[a].id << " and " << arm.links()[b].id << " touch in " << touching[a][b]
                                 << " of " << kSamples << " samples but are no self pair";
    }
  }
  EXPECT_GT(frequent, 10);
  // The hand folds into the upper arm: the palm and link_2 are a pair.
  const auto index = [&](const std::string& id) {
    for (size_t l = 0; l < n; ++l) if (arm.links()[l].id == id) return static_cast<uint32_t>(l);
    return uint32_t(-1);
  };
  const std::pair<uint32_t, uint32_t> pair(index("arm/link_2"), index("arm/palm"));
  EXPECT_NE(std::find(spheres.self_pairs.begin(), spheres.self_pairs.end(), pair), spheres.self_pairs.end());
}

TEST(MotionCollisionCheckerTest, NeverFreeWhereTheExactGeometryCollides) {
  for (const char* model : {"kuka_kr5_sixx_r850_barrett", "mitsubishi_pa10_pg70"}) {
    const auto s = TableScene(model);
    const ArmModel arm(*s.view.model, s.view.state, "arm");
    const CollisionChecker checker(arm, BuildSphereModel(*s.view.model, arm),
                                   CollectObstacles(*s.view.model, s.view.state, "arm"));
    const ExactChecker exact(*s.view.model, s.view.state, arm, checker.spheres(), {}, 0.003);
    std::mt19937_64 rng(17);
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    int free = 0, exact_collisions = 0;
    for (int i = 0; i < 400; ++i) {
      VecX q(arm.dof());
      for (size_t j = 0; j < arm.dof(); ++j) q[j] = arm.lower()[j] + unit(rng) * (arm.upper()[j] - arm.lower()[j]);
      const bool sphere_free = checker.IsValid(q);
      const std::string exact_why = exact.Explain(q);
      if (sphere_free) {
        EXPECT_EQ(exact_why, "") << model << " q = " << q.transpose();
      }
      free += sphere_free;
      exact_collisions += !exact_why.empty();
      if (!sphere_free) {
        EXPECT_NE(checker.Explain(q), "");
      }
    }
    EXPECT_GT(free, 20) << model;              // the test sees both outcomes
    EXPECT_GT(exact_collisions, 10) << model;
  }
}

TEST(MotionCollisionCheckerTest, ExplainsWhatTouchesWhat) {
  const auto s = TableScene("kuka_kr5_sixx_r850_barrett");
  const ArmModel arm(*s.view.model, s.view.state, "arm");
  const CollisionChecker checker(arm, BuildSphereModel(*s.view.model, arm),
                                 CollectObstacles(*s.view.model, s.view.state, "arm"));
  VecX q = VecX::Zero(6);
  EXPECT_EQ(checker.Explain(q), "");
  q[1] = 2.2;  // the upper arm leans forward, down through the post and the table
  EXPECT_NE(checker.Explain(q).find(" touches "), std::string::npos) << checker.Explain(q);
  q[1] = 9;
  EXPECT_NE(checker.Explain(q).find("arm/joint_a2 = 9 is outside its limits"), std::string::npos);
}

}  // namespace
}  // namespace graspsim::motion
