// Planning as a whole: same seed, same grasp set; obstacles respected; bad parameters rejected naming the field;
// grasp sets stored in SQLite and found again after the store is reopened (a server restart).
#include <unistd.h>

#include <cmath>
#include <filesystem>

#include <gtest/gtest.h>

#include "core/error.h"
#include "grasp/grasp_fixtures.h"
#include "grasp/planner.h"
#include "grasp/store.h"

namespace graspsim::grasp {
namespace {

using testing::PlanSmallSet;
using testing::ToMesh;

bool SameGrasps(const GraspSet& a, const GraspSet& b) {
  if (a.grasps.size() != b.grasps.size()) return false;
  for (size_t i = 0; i < a.grasps.size(); ++i) {
    const PlannedGrasp &x = a.grasps[i], &y = b.grasps[i];
    if (x.candidate_index != y.candidate_index || x.quality.epsilon != y.quality.epsilon ||
        x.hand_pose.position != y.hand_pose.position || x.joints != y.joints ||
        x.contacts.size() != y.contacts.size()) {
      return false;
    }
    for (size_t k = 0; k < x.contacts.size(); ++k) {
      if (x.contacts[k].point != y.contacts[k].point || x.contacts[k].normal != y.contacts[k].normal) return false;
    }
  }
  return true;
}

TEST(GraspPlannerTest, SameSeedGivesTheSameGraspSet) {
  GraspPlanner planner("schunk_pg70", ToMesh(collision::BoxMesh(Vec3(0.02, 0.03, 0.025))), {}, ClosingParams());
  const GraspSet a = PlanSmallSet(planner, 42), b = PlanSmallSet(planner, 42), c = PlanSmallSet(planner, 43);
  ASSERT_GT(a.grasps.size(), 3u);
  EXPECT_TRUE(SameGrasps(a, b));
  EXPECT_FALSE(SameGrasps(a, c));  // the seed matters: jittered samples and the candidate subset differ
}

TEST(GraspPlannerTest, GraspsNeverOverlapTheTable) {
  // A 5 cm cube standing on a table top (z <= -0.025 in the cube's frame).
  const LinkBox table{Vec3(0, 0, -0.025 - 0.02), Mat3::Identity(), Vec3(0.6, 0.4, 0.02)};
  ClosingParams params;
  GraspPlanner planner("schunk_pg70", ToMesh(collision::BoxMesh(Vec3::Constant(0.025))), {table}, params);
  const GraspSet set = PlanSmallSet(planner, 1);
  EXPECT_GT(set.collisions, 0u);  // approaches from below and low sides were discarded
  ASSERT_GT(set.grasps.size(), 0u);
  for (const PlannedGrasp& grasp : set.grasps) {
    std::vector<Pose> poses(planner.hand().links().size());
    planner.hand().LinkPoses(grasp.hand_pose, grasp.joints, &poses);
    for (size_t l = 0; l < poses.size(); ++l) {
      for (const LinkBox& box : planner.hand().links()[l].boxes) {
        const LinkBox placed{poses[l] * box.centre, poses[l].orientation.toRotationMatrix() * box.axes, box.half};
        EXPECT_FALSE(BoxesOverlap(placed, table, -params.contact_tolerance));
      }
    }
  }
}

void ExpectInvalid(const std::function<void()>& call, const std::string& field) {
  try {
    call();
    ADD_FAILURE() << "no error for " << field;
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::kInvalidArgument);
    EXPECT_EQ(std::string(e.what()).rfind(field + ":", 0), 0u) << e.what();
  }
}

TEST(GraspPlannerTest, BadParametersNameTheField) {
  auto mesh = ToMesh(collision::BoxMesh(Vec3::Constant(0.02)));
  ExpectInvalid([&] { GraspPlanner("ur5", mesh, {}, ClosingParams()); }, "hand");
  ClosingParams friction;
  friction.friction = 0;
  ExpectInvalid([&] { GraspPlanner("schunk_pg70", mesh, {}, friction); }, "friction");
  friction.friction = -0.3;
  ExpectInvalid([&] { GraspPlanner("schunk_pg70", mesh, {}, friction); }, "friction");
  GraspPlanner planner("schunk_pg70", mesh, {}, ClosingParams());
  CandidateParams zero;
  zero.circle_samples = 0;
  ExpectInvalid([&] { planner.Candidates(zero); }, "circle_samples");
  CandidateParams far;
  far.standoffs = {0.3};
  ExpectInvalid([&] { planner.Candidates(far); }, "standoffs[0]");
  CandidateParams shapes;
  shapes.preshapes = {7};
  ExpectInvalid([&] { planner.Candidates(shapes); }, "preshapes[0]");
}

TEST(GraspPlannerTest, CancelStopsThePlan) {
  GraspPlanner planner("schunk_pg70", ToMesh(collision::SphereMesh(0.03)), {}, ClosingParams());
  CandidateParams params;
  params.spacing = 0.005;
  const auto set = planner.Plan(planner.Candidates(params), 0, 0, [](size_t, size_t) { return false; });
  EXPECT_FALSE(set);
}

TEST(GraspStoreTest, SetsSurviveReopeningAndKeysSeparateParameters) {
  const std::string dir = (std::filesystem::temp_directory_path() /
                           ("graspsim_store_test_" + std::to_string(::getpid()))).string();
  std::filesystem::remove_all(dir);
  auto mesh = ToMesh(collision::BoxMesh(Vec3(0.02, 0.03, 0.025)));
  GraspPlanner planner("schunk_pg70", mesh, {}, ClosingParams());
  const GraspSet set = PlanSmallSet(planner, 42);
  CandidateParams params;
  params.seed = 42;
  const GraspSetKey key = MakeGraspSetKey("schunk_pg70", MeshHash(*mesh), {}, params, ClosingParams(), 0);
  {
    GraspStore store(dir);
    EXPECT_FALSE(store.Find(key.key));
    store.Put({key.key, "schunk_pg70", MeshHash(*mesh), key.params_text, 1.0, set});
  }
  GraspStore reopened(dir);
  const auto found = reopened.Find(key.key);
  ASSERT_TRUE(found);
  EXPECT_TRUE(SameGrasps(found->set, set));
  EXPECT_EQ(found->set.candidates, set.candidates);
  EXPECT_EQ(found->set.link_names, set.link_names);
  EXPECT_EQ(found->set.grasps[0].quality.volume, set.grasps[0].quality.volume);
  // Any parameter that decides the set changes the key.
  ClosingParams other;
  other.friction = 0.5;
  EXPECT_NE(MakeGraspSetKey("schunk_pg70", MeshHash(*mesh), {}, params, other, 0).key, key.key);
  params.seed = 43;
  EXPECT_NE(MakeGraspSetKey("schunk_pg70", MeshHash(*mesh), {}, params, ClosingParams(), 0).key, key.key);
  EXPECT_NE(MakeGraspSetKey("barrett_bh8_282", MeshHash(*mesh), {}, params, ClosingParams(), 0).key, key.key);
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace graspsim::grasp
