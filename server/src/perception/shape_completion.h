// Shape completion of a partially seen object (Bohg et al., ICRA 2011; PAPERS.md part C), one function per stage:
//
//   Observe  → the object's points and the camera's picture of them (observation.h)
//   Filter   → statistical outlier removal, optional voxel down-sampling (cloud_filters.h)
//   Symmetry → the best mirror plane perpendicular to the table by the visibility score (symmetry_search.h)
//   Normals  → plane fits over k neighbours (over a window of pixels for a depth image kept point for point), towards
//              the camera; mirrored points take reflected normals (normals.h);
//              with a known table, a cap of points over the footprint closes the underside
//   Surface  → screened Poisson on seen + mirrored points (poisson.h): a closed mesh, with the space the camera
//              saw empty (free_space.h) counted as outside
//
// or, for the paper's baseline, Observe → Filter → Delaunay sheet of 500 samples (delaunay_baseline.h).
// Single-threaded and deterministic: the same input gives the same mesh bit for bit.
#pragma once

#include <functional>
#include <optional>
#include <string>

#include "core/math.h"
#include "core/mesh.h"
#include "perception/delaunay_baseline.h"
#include "perception/observation.h"
#include "perception/poisson.h"
#include "perception/symmetry_search.h"

namespace graspsim {

enum class CompletionMethod { kMirror, kDelaunay };

struct CompletionOptions {
  CompletionMethod method = CompletionMethod::kMirror;
  int outlier_k = 8;            // statistical outlier removal: neighbours, 1..100
  double outlier_std = 2;       // and the cut in standard deviations; 0 = no outlier removal
  double voxel_size = 0;        // m; 0 = automatic (target_points)
  // With voxel_size 0, a cloud of more than target_points is voxel down-sampled to about that many points: voxel =
  // its median spacing × √(1.5 n / target_points) (a surface sampled every s holds ≈ A / s² points, cut by cubes
  // of side v it occupies ≈ 1.5 A / v²), enlarged once by √(count / target) when that gives over 1.2 × target.
  // The symmetry score, the normals and Poisson then cost the same for 39k points as for 1.5k: a depth camera's
  // cloud of a table-top object is far denser than a depth-5..7 grid resolves. 0 = never.
  size_t target_points = 1500;
  SymmetryParams symmetry;      // table_normal: world up unless the caller knows the table
  // The table the object stands on, {x : symmetry.table_normal · x = table_offset} (m), when known: the underside,
  // which no camera above the table sees, is then closed by a flat cap of points over the footprint (the convex
  // hull of the seen and mirrored points' projection), with normals into the table, instead of Poisson's bulge.
  std::optional<double> table_offset;
  int normal_k = 10;            // neighbours per normal, 3..100
  // Organized input the filter left point for point (a voxel below the pixel spacing, or none): the normals are
  // plane fits over a window of pixels spanning about this radius on the surface instead (normals.h,
  // EstimateImageNormals). 0: the k nearest in space, as for other clouds.
  double image_normal_radius = 0.004;
  // Space the camera saw empty is outside the completed surface (free_space.h): beyond the mask by more than
  // free_space_margin_px, or in front of the observed depth by more than free_space_depth_margin (m; ~3σ of a
  // depth camera's noise at table-top range). false: the surface is Poisson's alone.
  bool clear_seen_free_space = true;
  double free_space_margin_px = 1.5;
  double free_space_depth_margin = 0.004;
  PoissonParams poisson = [] { PoissonParams p; p.depth = 6; return p; }();
  DelaunayParams delaunay;
  size_t max_points = 2'000'000;  // points or pixels of the input (Limits::max_cloud_points)
};

struct StageTimings {
  double observe_ms = 0, filter_ms = 0, symmetry_ms = 0, normals_ms = 0, surface_ms = 0, total_ms = 0;
};

struct CompletionResult {
  TriangleMesh mesh;           // closed, counter-clockwise from outside, world frame, m
  std::optional<SymmetryPlane> plane;  // kMirror only
  size_t input_points = 0, filtered_points = 0, surface_points = 0;  // surface: seen + mirrored
  StageTimings ms;
  PoissonStats poisson;        // kMirror only
};

// Called between stages with the stage just started ("filter", "symmetry", "normals", "surface") and the
// fraction of the work done; returning false cancels (CompleteShape then returns nullopt).
using CompletionProgress = std::function<bool(const std::string& stage, double fraction)>;

// Throws graspsim::Error naming the field for bad input (observation.h, cloud_filters.h, the stages' params),
// kInvalidArgument when too few points survive the filter or they lie on a line.
std::optional<CompletionResult> CompleteShape(const PartialView& view, const CompletionOptions& options,
                                              const CompletionProgress& progress = {});

}  // namespace graspsim
