// What PlanGrasps, EvaluateGrasp and GetGraspSet ask of the grasp library, checked before any planning: the
// pre-shapes and the candidate method by name, the number of grasps kept, one candidate given by its parts, a
// stored set by its id. Errors name the request's field and the value (Error(kInvalidArgument) unless said).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "grasp/candidates.h"
#include "grasp/hand.h"
#include "grasp/simulate.h"
#include "grasp/store.h"

namespace graspsim::grasp {

constexpr size_t kDefaultMaxGrasps = 50;
constexpr uint64_t kMaxGraspsLimit = 10000;

// The pre-shapes named, as indices into hand.preshapes; none named: every pre-shape of the hand. An unknown name
// is "<field>[i]" (FindPreshape).
std::vector<uint32_t> PreshapeIndices(const HandSpec& hand, const std::vector<std::string>& names,
                                      const std::string& field = "preshapes");

// "" = bounding_box; else one of bounding_box, grasp_points, centroid_circles.
CandidateMethod CandidateMethodNamed(const std::string& field, const std::string& name);

// The grasps a plan keeps: 0 = kDefaultMaxGrasps; above kMaxGraspsLimit is refused.
size_t MaxGrasps(const std::string& field, uint64_t requested);

// One candidate as a caller gives it (EvaluateGrasp).
struct CandidateParts {
  Vec3 approach = Vec3::Zero();   // any length but zero: normalised
  Vec3 reference = Vec3::Zero();  // made perpendicular to the approach; zero or along it: any perpendicular
  Vec3 target = Vec3::Zero();
  double roll = 0;                // rad
  double standoff = 0;            // m, in [0, 0.2]
  std::string preshape;           // "" = the hand's default
};
// Errors name "<field>.approach", ".reference", ".target", ".roll", ".standoff", ".preshape".
Candidate CandidateFrom(const HandSpec& hand, const CandidateParts& parts, const std::string& field = "candidate");

// The stored set `id` (64 lowercase hex digits: kInvalidArgument otherwise). kFailedPrecondition without a
// store (`store` null: --grasp-data-dir=off), kNotFound for an id the store lacks.
StoredGraspSet FindStoredSet(const GraspStore* store, const std::string& field, const std::string& id);

}  // namespace graspsim::grasp
