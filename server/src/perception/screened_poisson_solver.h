// The linear system of screened Poisson reconstruction on a regular grid of N³ nodes (N = 2^depth + 1), in grid
// units (node spacing 1), and its solver:
//
//   (L + S) χ = b,   L = the 7-point graph Laplacian with natural (Neumann) borders,
//                    S = Σ_p β_p w_p w_pᵀ   (w_p: trilinear weights of sample p on its cell's 8 nodes),
//
// i.e. the minimiser of Σ_edges (χ_j − χ_i − V_ij)² + Σ_p β_p χ(p)² (Kazhdan & Hoppe 2013, eq. 3, on a grid): the
// gradient fits the splatted normal field V, and the screening pulls χ to 0 at the samples, which also fixes the
// constant the Neumann Laplacian leaves free. Solved by conjugate gradients preconditioned with one multigrid
// V-cycle (damped Jacobi with the lumped diagonal, full weighting, trilinear prolongation, coarse operators
// L_c/4 + lumped restricted screening, a dense Cholesky solve at 5³ nodes; screened_poisson_solver.cpp), and on the
// finer levels only near the samples (RefineInBand; band_solver.cpp). Single-threaded and in a fixed order: the
// same input gives the same bits.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

namespace graspsim {

struct ScreeningSample {
  int64_t base = 0;             // index of the cell's lowest node
  std::array<float, 8> weight;  // trilinear weights on corners (c & 1, c >> 1 & 1, c >> 2 & 1), times sqrt(β_p)
};

struct SolverReport {
  int iterations = 0;
  double relative_residual = 0;  // |b − A χ| / |b| at the end
};

// x: in, the initial guess (N³ values, x fastest); out, the solution. Iterates until the relative residual is
// below `tolerance` or `max_iterations`.
SolverReport SolveScreenedPoisson(int depth, const std::vector<ScreeningSample>& samples,
                                  const std::vector<float>& b, double tolerance, int max_iterations,
                                  std::vector<float>* x);

// The cascadic step of the solve (an octree's economy on a regular grid): on a grid one level finer than the one
// solved, χ is the coarse solution interpolated everywhere, and corrected only on a band of nodes near the samples,
// where the fine detail is, holding the rest fixed (Dirichlet). Conjugate gradients with a Jacobi preconditioner on
// the band's rows of L + S. `band`: N³ flags; every sample's cell and every node where b ≠ 0 must be in it.
// The relative residual is over the band's rows.
SolverReport RefineInBand(int depth, const std::vector<uint8_t>& band, const std::vector<ScreeningSample>& samples,
                          const std::vector<float>& b, double tolerance, int max_iterations, std::vector<float>* x);

// fine (2^(coarse_depth + 1) + 1 nodes per side) = the trilinear interpolation of coarse (2^coarse_depth + 1).
void ProlongTrilinear(int coarse_depth, const std::vector<float>& coarse, std::vector<float>* fine);

}  // namespace graspsim
