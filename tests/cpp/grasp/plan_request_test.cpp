// What PlanGrasps, EvaluateGrasp and GetGraspSet ask of the grasp library, checked without gRPC
// (grasp/plan_request.h): pre-shapes and methods by name, the number of grasps kept, one candidate given by its
// parts, a stored set by its id, the number of standoffs; every refusal names the field and the value.
#include "grasp/plan_request.h"

#include <cmath>
#include <filesystem>
#include <random>

#include <gtest/gtest.h>

#include "grasp/planner.h"
#include "test_util.h"

namespace graspsim::grasp {
namespace {

using test_util::ExpectError;

TEST(GraspPlanRequest, PreshapesAreNamedOrAll) {
  const HandSpec barrett = LoadHand("hand", "barrett_bh8_282");  // power, spherical, pinch
  EXPECT_EQ(PreshapeIndices(barrett, {"pinch", "power"}), (std::vector<uint32_t>{2, 0}));
  EXPECT_EQ(PreshapeIndices(barrett, {}), (std::vector<uint32_t>{0, 1, 2}));
  ExpectError([&] { PreshapeIndices(barrett, {"power", "fist"}); }, ErrorCode::kInvalidArgument,
              {"preshapes[1]: 'fist' is not a pre-shape of barrett_bh8_282", "spherical"});
}

TEST(GraspPlanRequest, MethodAndGraspCountHaveDefaultsAndLimits) {
  EXPECT_EQ(CandidateMethodNamed("method", ""), CandidateMethod::kBoundingBox);
  EXPECT_EQ(CandidateMethodNamed("method", "centroid_circles"), CandidateMethod::kCentroidCircles);
  ExpectError([] { CandidateMethodNamed("method", "darts"); }, ErrorCode::kInvalidArgument,
              {"method: 'darts' is not one of bounding_box, grasp_points, centroid_circles"});
  EXPECT_EQ(MaxGrasps("max_grasps", 0), kDefaultMaxGrasps);
  EXPECT_EQ(MaxGrasps("max_grasps", 7), 7u);
  EXPECT_EQ(MaxGrasps("max_grasps", kMaxGraspsLimit), kMaxGraspsLimit);
  ExpectError([] { MaxGrasps("max_grasps", 10001); }, ErrorCode::kInvalidArgument, {"max_grasps: 10001; at most 10000"});
  CandidateParams params;
  params.standoffs.assign(65, 0.0);
  ExpectError([&] { ValidateCandidateParams(params); }, ErrorCode::kInvalidArgument, {"standoffs: 65 values; at most 64"});
  params.standoffs.resize(64);
  ValidateCandidateParams(params);
}

TEST(GraspPlanRequest, ACandidateIsNormalisedAndCheckedByItsParts) {
  const HandSpec pg70 = LoadHand("hand", "schunk_pg70");
  CandidateParts parts;
  parts.approach = Vec3(0, 0, -2);
  parts.reference = Vec3(1, 0, 5);  // not perpendicular: its part along the approach is dropped
  parts.target = Vec3(0.01, 0, 0);
  parts.roll = 0.3;
  parts.standoff = 0.02;
  parts.preshape = "pinch";
  const Candidate c = CandidateFrom(pg70, parts);
  EXPECT_LT((c.approach - Vec3(0, 0, -1)).norm(), 1e-15);
  EXPECT_LT((c.reference - Vec3(1, 0, 0)).norm(), 1e-15);
  EXPECT_EQ(c.target, parts.target);
  EXPECT_EQ(c.roll, 0.3);
  EXPECT_EQ(c.standoff, 0.02);
  EXPECT_EQ(pg70.preshapes[c.preshape].name, "pinch");
  parts.reference = Vec3(0, 0, 3);  // along the approach: any perpendicular
  const Candidate along = CandidateFrom(pg70, parts);
  EXPECT_NEAR(along.reference.norm(), 1, 1e-12);
  EXPECT_NEAR(along.reference.dot(along.approach), 0, 1e-12);
  CandidateParts default_preshape;
  default_preshape.approach = Vec3::UnitZ();
  EXPECT_EQ(pg70.preshapes[CandidateFrom(pg70, default_preshape).preshape].name, "power");  // "" = the default

  const auto refused = [&](auto change, std::initializer_list<const char*> want) {
    CandidateParts p = parts;
    change(p);
    ExpectError([&] { CandidateFrom(pg70, p); }, ErrorCode::kInvalidArgument, want);
  };
  refused([](auto& p) { p.approach = Vec3::Zero(); }, {"candidate.approach: zero; give a direction"});
  refused([](auto& p) { p.approach.x() = NAN; }, {"candidate.approach"});
  refused([](auto& p) { p.target.y() = INFINITY; }, {"candidate.target"});
  refused([](auto& p) { p.roll = NAN; }, {"candidate.roll"});
  refused([](auto& p) { p.standoff = 0.3; }, {"candidate.standoff: 0.3 m is outside [0, 0.2] m"});
  refused([](auto& p) { p.standoff = -0.01; }, {"candidate.standoff: -0.01 m"});
  refused([](auto& p) { p.preshape = "spherical"; }, {"candidate.preshape: 'spherical' is not a pre-shape of schunk_pg70"});
}

TEST(GraspPlanRequest, AStoredSetIsFoundByItsId) {
  const auto dir = std::filesystem::temp_directory_path() / ("graspsim-plan-request-" + std::to_string(std::random_device()()));
  {
    GraspStore store(dir.string());
    const std::string id(64, 'a');
    ExpectError([&] { FindStoredSet(nullptr, "set_id", id); }, ErrorCode::kFailedPrecondition,
                {"set_id: the server stores no grasp sets (--grasp-data-dir=off)"});
    ExpectError([&] { FindStoredSet(&store, "set_id", "ABC"); }, ErrorCode::kInvalidArgument,
                {"set_id: 'ABC' is not a grasp-set id (64 lowercase hex digits)"});
    ExpectError([&] { FindStoredSet(&store, "grasp_set_id", id); }, ErrorCode::kNotFound,
                {"grasp_set_id: no stored grasp set '" "aaaa"});
    store.Put({id, "schunk_pg70", "hash", "params", 1, {}});
    EXPECT_EQ(FindStoredSet(&store, "set_id", id).hand, "schunk_pg70");
  }
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace graspsim::grasp
