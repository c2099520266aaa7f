// Friction per material pair: a contact's μ is that of its link's material and the object's (else the request's
// friction). Checked against the single-μ definition (which the quality tests check against analytic answers),
// by equivalences that must hold exactly, and by the store key and the input errors.
#include <gtest/gtest.h>

#include "core/error.h"
#include "grasp/grasp_fixtures.h"
#include "grasp/planner.h"
#include "grasp/store.h"

namespace graspsim::grasp {
namespace {

using testing::PlanSmallSet;
using testing::ToMesh;

std::shared_ptr<const TriangleMesh> Box() { return ToMesh(collision::BoxMesh(Vec3(0.02, 0.03, 0.025))); }

TEST(GraspMaterialsTest, PerLinkWrenchesAreEachContactsOwnCone) {
  // Three contacts 120° apart on a sphere, each link its own μ: the wrenches are, contact by contact, those of
  // the single-μ definition with that contact's μ.
  std::vector<GraspContact> c;
  for (int k = 0; k < 3; ++k) {
    const double a = 2 * M_PI * k / 3;
    const Vec3 p(0.04 * std::cos(a), 0.04 * std::sin(a), 0);
    c.push_back({p, -p.normalized(), k});
  }
  const std::vector<double> mu = {0.2, 0.5, 0.9};
  std::vector<Wrench> mixed, one;
  ContactWrenches(c.data(), c.size(), Vec3::Zero(), 0.04, mu, 8, &mixed);
  ASSERT_EQ(mixed.size(), 24u);
  for (size_t i = 0; i < c.size(); ++i) {
    ContactWrenches(&c[i], 1, Vec3::Zero(), 0.04, mu[i], 8, &one);
    for (size_t k = 0; k < 8; ++k) EXPECT_EQ(mixed[8 * i + k], one[k]) << i << " " << k;
  }
  // ε grows with any contact's μ: the mixed grasp lies between all-low and all-high.
  std::vector<Wrench> scratch;
  const double low = GraspQuality(c.data(), c.size(), Vec3::Zero(), 0.04, 0.2, 8, &scratch).epsilon;
  const double high = GraspQuality(c.data(), c.size(), Vec3::Zero(), 0.04, 0.9, 8, &scratch).epsilon;
  const Quality q = GraspQuality(c.data(), c.size(), Vec3::Zero(), 0.04, mu, 8, &scratch);
  EXPECT_TRUE(q.force_closure);
  EXPECT_GT(q.epsilon, low);
  EXPECT_LT(q.epsilon, high);
}

TEST(GraspMaterialsTest, PairsResolveInEitherOrderElseTheDefault) {
  ClosingParams p;
  p.friction = 0.4;
  p.friction_pairs = {{"rubber", "wood", 0.8}, {"default", "steel", 0.25}};
  EXPECT_EQ(PairFriction(p, "wood", "rubber"), 0.8);
  EXPECT_EQ(PairFriction(p, "rubber", "wood"), 0.8);
  EXPECT_EQ(PairFriction(p, "", "steel"), 0.25);  // "" is "default"
  EXPECT_EQ(PairFriction(p, "rubber", "steel"), 0.4);
  EXPECT_EQ(PairFriction(p, "", ""), 0.4);
}

TEST(GraspMaterialsTest, OnePairForEveryLinkEqualsThatFriction) {
  // Every PG70 link rubber on a wooden box at μ 0.8 is exactly the plan at friction 0.8; a table naming other
  // materials only changes nothing.
  ClosingParams materials;
  materials.object_material = "wood";
  materials.link_materials = {{"base_link", "rubber"}, {"finger_left", "rubber"}, {"finger_right", "rubber"}};
  materials.friction_pairs = {{"wood", "rubber", 0.8}, {"steel", "rubber", 0.1}};
  ClosingParams plain;
  plain.friction = 0.8;
  const GraspSet a = PlanSmallSet(GraspPlanner("schunk_pg70", Box(), {}, materials));
  const GraspSet b = PlanSmallSet(GraspPlanner("schunk_pg70", Box(), {}, plain));
  ASSERT_GT(a.grasps.size(), 3u);
  ASSERT_EQ(a.grasps.size(), b.grasps.size());
  for (size_t i = 0; i < a.grasps.size(); ++i) {
    EXPECT_EQ(a.grasps[i].candidate_index, b.grasps[i].candidate_index);
    EXPECT_EQ(a.grasps[i].quality.epsilon, b.grasps[i].quality.epsilon);
    EXPECT_EQ(a.grasps[i].quality.volume, b.grasps[i].quality.volume);
  }
}

TEST(GraspMaterialsTest, OneSlipperyJawLowersEpsilonToTheReference) {
  // The left jaw steel (μ 0.1), the rest default (0.4): every kept grasp's ε is that of its own contacts with
  // those μ, and no grasp beats the same contacts at 0.4 everywhere.
  ClosingParams params;
  params.link_materials = {{"finger_left", "steel"}};
  params.friction_pairs = {{"steel", "default", 0.1}};
  const GraspPlanner planner("schunk_pg70", Box(), {}, params);
  const GraspSet set = PlanSmallSet(planner);
  ASSERT_GT(set.grasps.size(), 0u);
  int left = -1;
  for (size_t l = 0; l < set.link_names.size(); ++l) left = set.link_names[l] == "finger_left" ? int(l) : left;
  ASSERT_GE(left, 0);
  const GraspObject& object = planner.object();
  std::vector<Wrench> scratch;
  for (const PlannedGrasp& g : set.grasps) {
    std::vector<double> mu(set.link_names.size(), 0.4);
    mu[left] = 0.1;
    const Quality expected = GraspQuality(g.contacts.data(), g.contacts.size(), object.centroid(),
                                          object.characteristic_length(), mu, 8, &scratch);
    EXPECT_EQ(g.quality.epsilon, expected.epsilon);
    const double uniform = GraspQuality(g.contacts.data(), g.contacts.size(), object.centroid(),
                                        object.characteristic_length(), 0.4, 8, &scratch).epsilon;
    EXPECT_LE(g.quality.epsilon, uniform * (1 + 1e-12));
  }
}

TEST(GraspMaterialsTest, StoreKeyAndBadInput) {
  const auto mesh = Box();
  const CandidateParams candidates;
  const ClosingParams plain;
  ClosingParams materials;
  materials.friction_pairs = {{"a", "b", 0.5}};
  ClosingParams swapped;
  swapped.friction_pairs = {{"b", "a", 0.5}};
  const std::string key = MakeGraspSetKey("schunk_pg70", MeshHash(*mesh), {}, candidates, plain, 0).key;
  EXPECT_EQ(MakeGraspSetKey("schunk_pg70", MeshHash(*mesh), {}, candidates, plain, 0).params_text.find("material"),
            std::string::npos);  // sets planned without materials keep their keys
  const std::string with = MakeGraspSetKey("schunk_pg70", MeshHash(*mesh), {}, candidates, materials, 0).key;
  EXPECT_NE(with, key);
  EXPECT_EQ(MakeGraspSetKey("schunk_pg70", MeshHash(*mesh), {}, candidates, swapped, 0).key, with);

  auto message = [&](const ClosingParams& p) {
    try {
      GraspPlanner("schunk_pg70", mesh, {}, p);
    } catch (const Error& e) {
      EXPECT_EQ(e.code(), ErrorCode::kInvalidArgument);
      return std::string(e.what());
    }
    return std::string("no error");
  };
  ClosingParams bad;
  bad.friction_pairs = {{"a", "b", 0.0}};
  EXPECT_NE(message(bad).find("friction_pairs[0].friction: 0"), std::string::npos) << message(bad);
  bad.friction_pairs = {{"a", "b", 0.5}, {"b", "a", 0.6}};
  EXPECT_NE(message(bad).find("friction_pairs[1]"), std::string::npos) << message(bad);
  bad.friction_pairs.clear();
  bad.link_materials = {{"thumb", "rubber"}};
  EXPECT_NE(message(bad).find("link_materials: 'thumb'"), std::string::npos) << message(bad);
}

}  // namespace
}  // namespace graspsim::grasp
