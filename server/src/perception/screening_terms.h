// The screening term S = Σ_p β_p w_p w_pᵀ of screened_poisson_solver.h, grouped by cell for fast products. Shared by
// the whole-grid multigrid solve and the band solve; internal to perception.
#pragma once

#include <algorithm>
#include <array>
#include <cstdint>
#include <vector>

#include "perception/screened_poisson_solver.h"

namespace graspsim::screening {

// S = Σ_p w_p w_pᵀ, grouped by cell: a cell holding one sample keeps its rank-1 weights (16 multiply-adds per
// product); a cell holding several sums their outer products into one 8 × 8 block (64), which on coarse grids —
// dozens of samples per cell — makes the screening term nearly free. Cells in grid order, samples within a cell
// in input order: deterministic.
struct ScreeningTerms {
  std::vector<int64_t> single_base, block_base;
  std::vector<std::array<float, 8>> single;
  std::vector<std::array<float, 64>> block;
};

inline ScreeningTerms GroupScreening(const std::vector<ScreeningSample>& samples) {
  std::vector<uint32_t> order(samples.size());
  for (uint32_t i = 0; i < order.size(); ++i) order[i] = i;
  std::stable_sort(order.begin(), order.end(),
                   [&samples](uint32_t a, uint32_t b) { return samples[a].base < samples[b].base; });
  ScreeningTerms terms;
  for (size_t first = 0; first < order.size();) {
    size_t last = first + 1;
    while (last < order.size() && samples[order[last]].base == samples[order[first]].base) ++last;
    const int64_t base = samples[order[first]].base;
    if (last - first == 1) {
      terms.single_base.push_back(base);
      terms.single.push_back(samples[order[first]].weight);
    } else {
      std::array<double, 64> sum{};
      for (size_t i = first; i < last; ++i) {
        const auto& w = samples[order[i]].weight;
        for (int c = 0; c < 8; ++c) {
          for (int d = 0; d < 8; ++d) sum[c * 8 + d] += double(w[c]) * w[d];
        }
      }
      std::array<float, 64> block;
      for (int e = 0; e < 64; ++e) block[e] = float(sum[e]);
      terms.block_base.push_back(base);
      terms.block.push_back(block);
    }
    first = last;
  }
  return terms;
}

// y[corner(base, c)] += (S x) over the terms; corner maps a cell's base and corner number to a vector index.
template <typename Corner>
void ApplyScreening(const ScreeningTerms& terms, const float* x, float* y, Corner corner) {
  int64_t at[8];
  float v[8];
  for (size_t t = 0; t < terms.single.size(); ++t) {
    float value = 0;
    for (int c = 0; c < 8; ++c) {
      at[c] = corner(terms.single_base[t], c);
      value += terms.single[t][c] * x[at[c]];
    }
    for (int c = 0; c < 8; ++c) y[at[c]] += terms.single[t][c] * value;
  }
  for (size_t t = 0; t < terms.block.size(); ++t) {
    for (int c = 0; c < 8; ++c) {
      at[c] = corner(terms.block_base[t], c);
      v[c] = x[at[c]];
    }
    const float* m = terms.block[t].data();
    for (int c = 0; c < 8; ++c) {
      float sum = 0;
      for (int d = 0; d < 8; ++d) sum += m[c * 8 + d] * v[d];
      y[at[c]] += sum;
    }
  }
}

// Row sums of S (the lumped screening of Jacobi's diagonal and of the coarse grids), added into `rows`.
template <typename Corner>
void AddScreeningRowSums(const ScreeningTerms& terms, float* rows, Corner corner) {
  for (size_t t = 0; t < terms.single.size(); ++t) {
    float sum = 0;
    for (float w : terms.single[t]) sum += w;
    for (int c = 0; c < 8; ++c) rows[corner(terms.single_base[t], c)] += terms.single[t][c] * sum;
  }
  for (size_t t = 0; t < terms.block.size(); ++t) {
    for (int c = 0; c < 8; ++c) {
      float sum = 0;
      for (int d = 0; d < 8; ++d) sum += terms.block[t][c * 8 + d];
      rows[corner(terms.block_base[t], c)] += sum;
    }
  }
}

inline int64_t CornerOffset(int n, int corner) {
  return (corner & 1) + int64_t(corner >> 1 & 1) * n + int64_t(corner >> 2 & 1) * n * n;
}

}  // namespace graspsim::screening
