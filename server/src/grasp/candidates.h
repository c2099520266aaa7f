// Grasp candidate generators (PAPERS.md part C):
// - bounding box: the object's box padded by `padding`, each face sampled every `spacing` (stratified, jittered
//   by the seed), a ray from each sample into the object; approach = the negated surface normal at the hit;
// - grasp points: two contact points (given, or the ends of the object's minor axis through the centroid);
//   approaches on the circle whose normal is the point-to-point axis, `circle_samples` over [0°, 180°); the hand's
//   closing direction (+y) along the axis at roll 0;
// - centroid circles: approaches toward the centroid from a circle around it whose normal is the major
//   eigenvector, plus the perpendicular circle (normal: the middle eigenvector), `circle_samples` each over 360°.
// Every approach is crossed with the pre-shapes, standoffs and rolls (k · roll_period / rolls).
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "grasp/grasp_object.h"
#include "grasp/simulate.h"

namespace graspsim::grasp {

enum class CandidateMethod { kBoundingBox, kGraspPoints, kCentroidCircles };

struct CandidateParams {
  CandidateMethod method = CandidateMethod::kBoundingBox;
  double spacing = 0.02;                  // m, bounding-box face sampling δ
  double padding = 0.01;                  // m
  int circle_samples = 8;                 // approaches per circle
  std::optional<std::pair<Vec3, Vec3>> grasp_points;  // object frame, m
  std::vector<uint32_t> preshapes = {0};  // pre-shape indices
  std::vector<double> standoffs = {0.0};  // m
  int rolls = 4;
  uint64_t seed = 1;
  size_t max_candidates = 0;              // 0 = all; else a seeded random subset of this size, in order
};

// Deterministic for equal inputs and seed (its own generator, no std:: distributions whose output varies
// between standard libraries).
std::vector<Candidate> GenerateCandidates(const GraspObject& object, double roll_period, const CandidateParams& params);

// "bounding_box", "grasp_points", "centroid_circles".
std::optional<CandidateMethod> ParseCandidateMethod(const std::string& name);
const char* CandidateMethodName(CandidateMethod method);

}  // namespace graspsim::grasp
