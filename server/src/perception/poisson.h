// Screened Poisson surface reconstruction (Kazhdan & Hoppe 2013) on a regular grid: a closed, consistently
// oriented mesh through oriented points (PAPERS.md part C, "Surface"; issue 5, stage 5).
//
// The stages, one function each in poisson.cpp:
//   1. Grid:    a cube of side scale × (the cloud's largest extent), centred on its bounding box, with
//               2^depth cells per side (spacing h). The samples of one finest cell merge into one (mean position,
//               mean unit normal): each occupied cell counts once, whatever the sampling's density.
//   2. Splat:   each sample carries its normal times the surface area it stands for (a = A / N, the area A
//               estimated from the cells the samples occupy, N the merged samples) into the gradient field V on the grid's edges,
//               spread by a tent kernel of half-width max(2 cells, √a) — two cells at least, because a
//               one-cell (trilinear) splat aliases the samples' positions in their cells into bumps of ~h/50;
//               wider for sparse clouds, so they leave no gaps. Only b = Dᵀ V is stored.
//   3. Solve:   the indicator χ minimising Σ_edges (∇χ − V)² + α (a / h²) Σ_p χ(p)² (screened_poisson_solver.h);
//               χ jumps by ≈ 1 across the surface, low inside. Coarse to fine: the whole grid at depth ≤ 5
//               (multigrid-preconditioned CG), then each finer level interpolated and corrected only in a band
//               a few cells around the samples — far from them χ is flat, which is the economy of Kazhdan's
//               octree on a regular grid. Levels finer than refine_limit × the sample spacing are interpolated.
//   4. Iso:     the mean of χ at the samples.
//   5. Extract: marching cubes at that iso-value (marching_cubes.h): triangles counter-clockwise from outside.
// The grid's border lies (scale − 1)/2 of the extent beyond the cloud; it counts as outside for the extraction,
// and so does everything beyond the samples' bounding box grown by clip_cells: where a one-sided cloud's inside
// leaks there the mesh still closes (clipped by the box) instead of ballooning into the margin.
#pragma once

#include <functional>
#include <vector>

#include "core/math.h"
#include "core/mesh.h"

namespace graspsim {

struct PoissonParams {
  int depth = 7;            // 2^depth cells per side, 5..8 (the paper's octree depths 5 and 7)
  double screening = 4;     // α in (0, 1e4]: weight of χ = 0 at the samples against fitting the normals; it also
                            // fixes the constant the Neumann problem leaves free, so it cannot be 0
  double scale = 1.25;      // grid cube side / the cloud's largest extent, 1.05..4
  double tolerance = 1e-3;  // conjugate gradients stop at this relative residual, (0, 0.1]
  int max_iterations = 60;  // 1..1000
  // Levels whose cell is below refine_limit × the sample spacing (√a) are interpolated from the coarser level, not
  // solved: a sparse cloud has no detail there, and its band would be fat (an octree stops subdividing where a
  // node holds too few samples; PCL's default samples_per_node is 1). 0.35: solve while the samples are at most
  // about three cells apart (2.1k points on a 10 cm sphere: depth 6 solved, 7 interpolated; 0.012 mm deviation
  // against 0.004 mm solving depth 7 too, in a fifth of the time). 0..4; 0 solves every level.
  double refine_limit = 0.35;
  // The surface is clipped to the samples' bounding box grown by this many cells (negative: only at the grid's
  // border): a one-sided cloud's indicator no longer balloons into the grid's margin (poisson.cpp, ClipToSamples).
  double clip_cells = 2;
};

struct PoissonStats {
  double ms_grid_splat = 0, ms_solve = 0, ms_iso = 0, ms_extract = 0;  // wall time per stage
  int solver_iterations = 0;
  double solver_relative_residual = 0;
  double iso_value = 0;
  double cell_size = 0;      // h, m
  double sample_area = 0;    // a, m² per sample
  int solved_depth = 0;      // the finest level solved; finer ones up to depth interpolated (refine_limit)
};

struct PoissonResult {
  TriangleMesh mesh;
  PoissonStats stats;
};

// points and normals (one per point, any length > 0; outward) in m. Throws Error(kInvalidArgument) naming the
// field and value for an empty cloud, points all on a line (or all equal), non-finite or zero normals, a count
// mismatch, or parameters outside their ranges.
// `known_outside`, when given, names space the caller knows holds no object (shape completion: space the camera
// saw empty, free_space.h): grid nodes there count as outside for the extraction, as the border does.
using KnownOutside = std::function<bool(const Vec3& point)>;
PoissonResult ReconstructSurface(const std::vector<Vec3>& points, const std::vector<Vec3>& normals,
                                 const PoissonParams& params = {}, const KnownOutside& known_outside = {});

}  // namespace graspsim
