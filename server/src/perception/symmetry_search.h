// The symmetry search of Bohg et al. (PAPERS.md part C, "Shape prediction by planar symmetry"): the object's
// symmetry plane, assumed perpendicular to the table, found by generate-and-test.
//
//   1. Project the cloud onto the table plane; its centroid c and the two eigenvectors of its 2D covariance.
//      The initial plane contains the eigenvector most perpendicular to the viewing direction v (camera → c), so
//      its normal n₀ points roughly away from the camera and mirroring moves the seen side to the back. A nearly
//      isotropic projection (eigenvalue ratio ≥ 0.8, e.g. a cylinder's disc) has no meaningful eigenvectors: n₀ is
//      then the viewing direction itself.
//   2. Hypotheses: n orientations α in [−max_angle, max_angle] about the table normal × m shifts d along the
//      rotated plane normal n_α, d in [0, shift_range × max_p (p − c)·n_α] (0: the plane through the centroid;
//      the far end: the plane through the farthest seen point). Orientations are tried by |α| ascending, shifts
//      ascending, and a later hypothesis wins only when its score is lower by more than 0.002 px²: the
//      visibility score cannot see a plane placed too far back (its mirrored points all hide behind the seen
//      surface), so among equal scores the nearest plane is the plausible one.
//   3. Mirror: Q = P − 2 ((P − o) · n) n, o = c + d n_α (the paper's Q = R⁻¹(−R(P + d − c)) + c).
//   4. Score (lower is better): each Q projected into the camera image.
//        outside the mask:                    δ1 = squared distance to the nearest mask pixel (px², OpenCV's
//                                             distance transform over the mask's bounding box + a margin of
//                                             max(16 px, half its size); beyond that window, the window's edge
//                                             value plus the squared overshoot)
//        inside, in front of the observed depth by more than depth_tolerance:
//                                             δ2 = the depth difference in pixels (m × f / z, so both terms are in
//                                             image units)
//      score = (Σ_{Q∉mask} δ1 + Σ_{Q∈mask} δ2) / |Q|: the paper's eq. 3, E_{Q∉mask}[δ1] + E_{Q∈mask}[δ2], but
//      with both expectations over all mirrored points (a point contributes 0 to the term it is not in). Taken
//      literally, eq. 3 averages each term over its own subset, so one point crossing the mask's edge makes the
//      score jump from 0 to ≥ 1 px² however many points fit: the minimum then lands wherever no point happens to
//      cross, a millimetre or more off (measured on the cylinder of shape_completion_test.cpp: 1.3 mm).
//   5. Optional refinements (not in the paper): the grid again, n × m, spanning ± one step around the best
//      hypothesis (kept inside the ranges of 2.), so the plane is found to a fraction of a coarse step.
//   6. The shift refined (not in the paper): at the best orientation, fine_shifts shifts across ± one step of the
//      last pass (an eighth of a step apart at the default 17). The paper's 5 shifts reach 1.25 × the farthest seen
//      point; for a hollow object seen from above that is the inner far wall, so they step 16 mm apart on the YCB
//      mug and none falls near its axis, where the score's minimum is. Over the 64 views of `tests/bench/run
//      shape` (all points, depth 5) this took the mean deviation completion → truth from 3.20 to 2.55 mm and the
//      centroid error from 3.28 to 2.79 % (the mug's from 7.5 to 5.1 mm); its 17 scores add 0.4–0.9 ms to the
//      stage's ~5 ms.
#pragma once

#include <vector>

#include "core/math.h"
#include "perception/observation.h"

namespace graspsim {

struct SymmetryParams {
  Vec3 table_normal = Vec3::UnitZ();  // world, unit: the plane's normal is perpendicular to it
  int orientations = 7;               // n, 1..50 (7 × 5 = the paper's 35 hypotheses)
  int shifts = 5;                     // m, 1..50
  double max_angle_deg = 20;          // the orientations span ± this, 0..90
  double shift_range = 1.25;          // see 2., 0..4
  double depth_tolerance = 0;         // m: a mirrored point this close in front is not penalised (it biases the
                                      // plane towards the camera by about half of it, so 0 unless told)
  int refinements = 0;                // finer passes around the best hypothesis, 0..5
  int fine_shifts = 17;               // step 6's shifts, 2..100; 0 = none (the paper's grid alone)
  // Hypotheses are scored on at most this many of the points, every ⌈N / score_points⌉-th (the score is a mean
  // per mirrored point; a few hundred pin it to well under the tie tolerance). 0 = all; else 50..100000.
  int score_points = 500;
};

struct SymmetryPlane {
  Vec3 point = Vec3::Zero();    // on the plane, world, m
  Vec3 normal = Vec3::UnitX();  // unit, world, horizontal, pointing away from the camera
  double score = 0;             // the best hypothesis's score (px² + px)
  double angle_deg = 0;         // α of the best hypothesis relative to the initial plane
  double shift = 0;             // d of the best hypothesis, m
  int hypotheses = 0;           // hypotheses scored
};

// Reflection of points and directions across a plane.
Vec3 MirrorPoint(const SymmetryPlane& plane, const Vec3& p);
Vec3 MirrorDirection(const SymmetryPlane& plane, const Vec3& d);

// Scores hypotheses against one observation (holds the mask's distance transform).
class SymmetrySearch {
 public:
  explicit SymmetrySearch(const Observation& observation);
  // The score of mirroring `points` across `plane` (step 4); depth_tolerance in m.
  double Score(const std::vector<Vec3>& points, const SymmetryPlane& plane, double depth_tolerance) const;
  // Steps 1–5 over `points` (a filtered subset of the observation's, ≥ 3, not all on a vertical line).
  SymmetryPlane Find(const std::vector<Vec3>& points, const SymmetryParams& params) const;

 private:
  const Observation& observation_;
  // Per pixel of the window [x0, x0 + w) × [y0, y0 + h) around the mask: squared distance to the nearest mask
  // pixel (0 inside), px². Every mask pixel is inside, so the values there are exact; a window instead of the whole
  // image keeps the transform's cost at the object's size (a 1.3 Mpx image for 39k points: 30 ms → ~1 ms).
  int x0_ = 0, y0_ = 0, w_ = 0, h_ = 0;
  std::vector<float> outside_sq_;
};

// Range checks of the parameters (kInvalidArgument naming the field).
void ValidateSymmetryParams(const SymmetryParams& params);

}  // namespace graspsim
