// The band solve of screened_poisson_solver.h (RefineInBand): the finer levels' correction near the samples.
#include <array>
#include <cmath>
#include <cstdint>
#include <vector>

#include "perception/screened_poisson_solver.h"
#include "perception/screening_terms.h"

namespace graspsim {

using screening::AddScreeningRowSums;
using screening::ApplyScreening;
using screening::CornerOffset;
using screening::GroupScreening;
using screening::ScreeningTerms;

SolverReport RefineInBand(int depth, const std::vector<uint8_t>& band, const std::vector<ScreeningSample>& samples,
                          const std::vector<float>& b, double tolerance, int max_iterations, std::vector<float>* x) {
  const int n = (1 << depth) + 1;
  const int64_t stride[3] = {1, n, int64_t(n) * n};
  // The band's nodes in grid order, a map back from the grid, and each node's in-band neighbours (−1: fixed).
  std::vector<int64_t> nodes;
  std::vector<std::array<int16_t, 3>> coords;  // (i, j, k) of each band node: no divisions later
  std::vector<int32_t> slot(band.size(), -1);
  int64_t at = 0;
  for (int k = 0; k < n; ++k) {
    for (int j = 0; j < n; ++j) {
      for (int i = 0; i < n; ++i, ++at) {
        if (!band[at]) continue;
        slot[at] = int32_t(nodes.size());
        nodes.push_back(at);
        coords.push_back({int16_t(i), int16_t(j), int16_t(k)});
      }
    }
  }
  const size_t m = nodes.size();
  std::vector<std::array<int32_t, 6>> neighbours(m);
  std::vector<float> degree(m), fixed_sum(m), inv_diag(m);
  for (size_t r = 0; r < m; ++r) {
    int count = 0;
    float outside = 0;
    for (int a = 0; a < 3; ++a) {
      for (int side = 0; side < 2; ++side) {
        int32_t& nb = neighbours[r][2 * a + side];
        nb = -1;
        if (side == 0 ? coords[r][a] == 0 : coords[r][a] + 1 == n) continue;  // natural border: no neighbour
        const int64_t j = nodes[r] + (side == 0 ? -stride[a] : stride[a]);
        ++count;
        if (slot[j] >= 0) nb = slot[j];
        else outside += (*x)[j];
      }
    }
    degree[r] = float(count);
    fixed_sum[r] = outside;
  }
  // The screening terms with their corners' band slots looked up once (the slot map is too big to stay cached).
  ScreeningTerms screening = GroupScreening(samples);
  auto to_slots = [&slot, n](std::vector<int64_t>* bases, std::vector<std::array<int32_t, 8>>* corners) {
    corners->resize(bases->size());
    for (size_t t = 0; t < bases->size(); ++t) {
      for (int c = 0; c < 8; ++c) (*corners)[t][c] = slot[(*bases)[t] + CornerOffset(n, c)];
      (*bases)[t] = int64_t(t);
    }
  };
  std::vector<std::array<int32_t, 8>> single_slots, block_slots;
  to_slots(&screening.single_base, &single_slots);
  to_slots(&screening.block_base, &block_slots);
  const size_t singles = single_slots.size();
  // Term t < singles is single t; after that, block t − singles (ApplyScreening walks singles then blocks).
  for (auto& b : screening.block_base) b += int64_t(singles);
  auto band_corner = [&](int64_t term, int c) {
    return int64_t(term < int64_t(singles) ? single_slots[term][c] : block_slots[term - singles][c]);
  };
  std::vector<float> lumped(m, 0.0f);
  AddScreeningRowSums(screening, lumped.data(), band_corner);
  for (size_t r = 0; r < m; ++r) inv_diag[r] = 1.0f / (degree[r] + lumped[r]);
  // Neighbours off the band read a zero kept at slot m (the correction vanishes there): no branch per neighbour.
  for (auto& list : neighbours) {
    for (int32_t& nb : list) nb = nb < 0 ? int32_t(m) : nb;
  }
  auto apply = [&](std::vector<float>& v, std::vector<float>* y) {
    v[m] = 0;
    for (size_t r = 0; r < m; ++r) {
      const auto& nb = neighbours[r];
      (*y)[r] = degree[r] * v[r] - v[nb[0]] - v[nb[1]] - v[nb[2]] - v[nb[3]] - v[nb[4]] - v[nb[5]];
    }
    ApplyScreening(screening, v.data(), y->data(), band_corner);
  };
  // r = b − A x on the band rows, the fixed neighbours' values included.
  std::vector<float> current(m + 1), residual(m), z(m), p(m + 1), q(m), delta(m, 0.0f);
  for (size_t r = 0; r < m; ++r) current[r] = (*x)[nodes[r]];
  apply(current, &q);
  double b_norm2 = 0;
  for (size_t r = 0; r < m; ++r) {
    residual[r] = b[nodes[r]] + fixed_sum[r] - q[r];
    b_norm2 += double(b[nodes[r]]) * b[nodes[r]];
  }
  SolverReport report;
  const double b_norm = std::sqrt(b_norm2);
  if (b_norm == 0 || m == 0) return report;
  auto dot = [m](const std::vector<float>& u, const std::vector<float>& v) {
    double sum = 0;
    for (size_t r = 0; r < m; ++r) sum += double(u[r]) * v[r];
    return sum;
  };
  for (size_t r = 0; r < m; ++r) p[r] = z[r] = inv_diag[r] * residual[r];
  double rz = dot(residual, z);
  report.relative_residual = std::sqrt(dot(residual, residual)) / b_norm;
  while (report.relative_residual > tolerance && report.iterations < max_iterations) {
    apply(p, &q);
    const double pq = dot(p, q);
    if (!(pq > 0)) break;
    const float alpha = float(rz / pq);
    for (size_t r = 0; r < m; ++r) {
      delta[r] += alpha * p[r];
      residual[r] -= alpha * q[r];
    }
    ++report.iterations;
    report.relative_residual = std::sqrt(dot(residual, residual)) / b_norm;
    for (size_t r = 0; r < m; ++r) z[r] = inv_diag[r] * residual[r];
    const double rz_next = dot(residual, z);
    const float beta = float(rz_next / rz);
    rz = rz_next;
    for (size_t r = 0; r < m; ++r) p[r] = z[r] + beta * p[r];
  }
  for (size_t r = 0; r < m; ++r) (*x)[nodes[r]] += delta[r];
  return report;
}

}  // namespace graspsim
