#include "perception/screened_poisson_solver.h"

#include <algorithm>
#include <cmath>
#include <memory>
#include <utility>

#include <Eigen/Cholesky>
#include <Eigen/Core>

#include "perception/screening_terms.h"

namespace graspsim {
namespace {

using screening::AddScreeningRowSums;
using screening::ApplyScreening;
using screening::CornerOffset;
using screening::GroupScreening;
using screening::ScreeningTerms;

constexpr int kCoarsestDepth = 2;  // 5³ nodes: a dense Cholesky solve is instant
constexpr int kSmoothingSweeps = 2;
constexpr float kJacobiDamping = 0.8f;  // with the lumped diagonal, D⁻¹A ≤ 2: any ω ≤ 1 is stable

// fine += trilinear interpolation of the coarse grid (nc nodes per side, fine 2 nc − 1), one axis at a time (x, y,
// z), whole rows and planes per step: an even fine index copies its coarse node, an odd one averages two.
// `scratch` holds the two partial results (no allocation once it has grown).
void ProlongAdd(int nc, const std::vector<float>& coarse, std::vector<float>* fine, std::vector<float>* scratch) {
  const int64_t nf = 2 * int64_t(nc) - 1, c = nc;
  scratch->resize(nf * c * c + nf * nf * c);
  float* along_x = scratch->data();            // nf × nc × nc
  float* along_xy = along_x + nf * c * c;      // nf × nf × nc
  for (int64_t row = 0; row < c * c; ++row) {
    const float* in = coarse.data() + row * c;
    float* out = along_x + row * nf;
    for (int64_t i = 0; i + 1 < c; ++i) {
      out[2 * i] = in[i];
      out[2 * i + 1] = 0.5f * (in[i] + in[i + 1]);
    }
    out[nf - 1] = in[c - 1];
  }
  for (int64_t k = 0; k < c; ++k) {
    for (int64_t j = 0; j < nf; ++j) {
      const float* in = along_x + (k * c + j / 2) * nf;
      float* out = along_xy + (k * nf + j) * nf;
      if (j & 1) {
        for (int64_t i = 0; i < nf; ++i) out[i] = 0.5f * (in[i] + in[i + nf]);
      } else {
        std::copy(in, in + nf, out);
      }
    }
  }
  const int64_t plane = nf * nf;
  for (int64_t k = 0; k < nf; ++k) {
    const float* in = along_xy + (k / 2) * plane;
    float* out = fine->data() + k * plane;
    if (k & 1) {
      for (int64_t i = 0; i < plane; ++i) out[i] += 0.5f * (in[i] + in[i + plane]);
    } else {
      for (int64_t i = 0; i < plane; ++i) out[i] += in[i];
    }
  }
}

// One grid of the hierarchy: A = c L + (exact samples on the finest grid | diag(s) on the coarser ones).
struct Level {
  int n = 0;                       // nodes per side
  float c = 1;                     // Laplacian coefficient: 1 on the finest grid, ÷4 per coarsening
  std::vector<float> s;            // lumped screening (row sums of S, restricted by full weighting)
  std::vector<float> inv_diag;     // 1 / (c · degree + s): Jacobi's diagonal
  std::vector<float> x, b, r;      // V-cycle work vectors
  int64_t size() const { return int64_t(n) * n * n; }
};

class Multigrid {
 public:
  Multigrid(int depth, const std::vector<ScreeningSample>& samples) : screening_(GroupScreening(samples)) {
    levels_.resize(depth + 1);
    for (int d = depth; d >= kCoarsestDepth; --d) {
      Level& level = levels_[d];
      level.n = (1 << d) + 1;
      level.c = d == depth ? 1.0f : levels_[d + 1].c / 4;
      if (d == depth) {
        level.s.assign(level.size(), 0);
        const int n = level.n;
        AddScreeningRowSums(screening_, level.s.data(), [n](int64_t base, int c) { return base + CornerOffset(n, c); });
      } else {
        level.s.resize(level.size());
        Restrict(levels_[d + 1].n, levels_[d + 1].s, &level.s, &scratch_);
      }
      level.inv_diag.resize(level.size());
      ForEachNode(level.n, [&](int64_t i, int degree) { level.inv_diag[i] = 1.0f / (level.c * degree + level.s[i]); });
      level.x.resize(level.size());
      level.b.resize(level.size());
      level.r.resize(level.size());
    }
    FactorCoarsest();
  }

  // y = A x on grid d.
  void Apply(int d, const std::vector<float>& x, std::vector<float>* y) const {
    const Level& level = levels_[d];
    const int n = level.n;
    const int64_t sy = n, sz = int64_t(n) * n;
    float* out = y->data();
    const float* in = x.data();
    for (int k = 0; k < n; ++k) {
      for (int j = 0; j < n; ++j) {
        const int64_t row = k * sz + j * sy;
        if (k == 0 || j == 0 || k + 1 == n || j + 1 == n) {
          for (int i = 0; i < n; ++i) out[row + i] = level.c * BorderSum(in, row + i, i, j, k, n);
          continue;
        }
        // Interior rows: six neighbours each, no branches (the loop vectorises); the row's ends are borders.
        out[row] = level.c * BorderSum(in, row, 0, j, k, n);
        const float* centre = in + row;
        const float *west = centre - 1, *east = centre + 1, *south = centre - sy, *north = centre + sy,
                    *down = centre - sz, *up = centre + sz;
        float* o = out + row;
        for (int i = 1; i + 1 < n; ++i) {
          o[i] = level.c * (6 * centre[i] - west[i] - east[i] - south[i] - north[i] - down[i] - up[i]);
        }
        out[row + n - 1] = level.c * BorderSum(in, row + n - 1, n - 1, j, k, n);
      }
    }
    if (d + 1 == int(levels_.size())) {
      ApplyScreening(screening_, in, out, [n](int64_t base, int c) { return base + CornerOffset(n, c); });
    } else {
      for (int64_t i = 0; i < level.size(); ++i) out[i] += level.s[i] * in[i];
    }
  }

  // z ≈ A⁻¹ r by one V-cycle from zero: symmetric (same sweeps down and up, restriction ∝ prolongationᵀ), so it
  // is a valid preconditioner for conjugate gradients.
  void Precondition(const std::vector<float>& r, std::vector<float>* z) {
    const int top = int(levels_.size()) - 1;
    levels_[top].b = r;
    VCycle(top);
    *z = levels_[top].x;
  }

 private:
  // The Laplacian's row at a node that may lie on the grid's border (fewer neighbours: natural boundary).
  static float BorderSum(const float* in, int64_t at, int i, int j, int k, int n) {
    const int64_t sy = n, sz = int64_t(n) * n;
    const float v = in[at];
    float sum = 0;
    if (i > 0) sum += v - in[at - 1];
    if (i + 1 < n) sum += v - in[at + 1];
    if (j > 0) sum += v - in[at - sy];
    if (j + 1 < n) sum += v - in[at + sy];
    if (k > 0) sum += v - in[at - sz];
    if (k + 1 < n) sum += v - in[at + sz];
    return sum;
  }

  template <typename Fn>
  static void ForEachNode(int n, Fn fn) {
    int64_t at = 0;
    for (int k = 0; k < n; ++k) {
      for (int j = 0; j < n; ++j) {
        for (int i = 0; i < n; ++i, ++at) {
          fn(at, (i > 0) + (i + 1 < n) + (j > 0) + (j + 1 < n) + (k > 0) + (k + 1 < n));
        }
      }
    }
  }

  // Full weighting from a fine grid of nf = 2 nc − 1 nodes per side, one axis at a time (x, y, z) over whole rows and
  // planes: (¼, ½, ¼) about the coinciding node (½ of it on a border, where the grid ends): restriction =
  // prolongationᵀ / 8. `coarse` must hold nc³ values; `scratch` the partial results.
  static void Restrict(int nf_int, const std::vector<float>& fine, std::vector<float>* coarse,
                       std::vector<float>* scratch) {
    const int64_t nf = nf_int, c = (nf + 1) / 2;
    scratch->resize(c * nf * nf + c * c * nf);
    float* along_x = scratch->data();        // nc × nf × nf
    float* along_xy = along_x + c * nf * nf;  // nc × nc × nf
    // One (¼, ½, ¼) step between rows of `count` values: out = ½ centre + ¼ below (if any) + ¼ above (if any).
    const auto weigh = [](const float* centre, const float* below, const float* above, float* out, int64_t count) {
      for (int64_t i = 0; i < count; ++i) {
        float sum = 0.5f * centre[i];
        if (below) sum += 0.25f * below[i];
        if (above) sum += 0.25f * above[i];
        out[i] = sum;
      }
    };
    for (int64_t row = 0; row < nf * nf; ++row) {
      const float* in = fine.data() + row * nf;
      float* out = along_x + row * c;
      out[0] = 0.5f * in[0] + 0.25f * in[1];
      for (int64_t i = 1; i + 1 < c; ++i) {
        float sum = 0.5f * in[2 * i];
        sum += 0.25f * in[2 * i - 1];
        sum += 0.25f * in[2 * i + 1];
        out[i] = sum;
      }
      out[c - 1] = 0.5f * in[nf - 1] + 0.25f * in[nf - 2];
    }
    for (int64_t k = 0; k < nf; ++k) {
      for (int64_t j = 0; j < c; ++j) {
        const float* centre = along_x + (k * nf + 2 * j) * c;
        weigh(centre, j > 0 ? centre - c : nullptr, j + 1 < c ? centre + c : nullptr, along_xy + (k * c + j) * c, c);
      }
    }
    const int64_t plane = c * c;
    for (int64_t k = 0; k < c; ++k) {
      const float* centre = along_xy + 2 * k * plane;
      weigh(centre, k > 0 ? centre - plane : nullptr, k + 1 < c ? centre + plane : nullptr,
            coarse->data() + k * plane, plane);
    }
  }

  void Smooth(int d) {
    Level& level = levels_[d];
    Apply(d, level.x, &level.r);
    for (int64_t i = 0; i < level.size(); ++i) {
      level.x[i] += kJacobiDamping * level.inv_diag[i] * (level.b[i] - level.r[i]);
    }
  }

  void VCycle(int d) {
    Level& level = levels_[d];
    if (d == kCoarsestDepth) {
      const Eigen::VectorXd rhs = Eigen::Map<const Eigen::VectorXf>(level.b.data(), level.size()).cast<double>();
      Eigen::Map<Eigen::VectorXf>(level.x.data(), level.size()) = coarsest_->solve(rhs).cast<float>();
      return;
    }
    // The first sweep from x = 0 needs no product: x = ω D⁻¹ b.
    for (int64_t i = 0; i < level.size(); ++i) level.x[i] = kJacobiDamping * level.inv_diag[i] * level.b[i];
    for (int sweep = 1; sweep < kSmoothingSweeps; ++sweep) Smooth(d);
    Apply(d, level.x, &level.r);
    for (int64_t i = 0; i < level.size(); ++i) level.r[i] = level.b[i] - level.r[i];
    Restrict(level.n, level.r, &levels_[d - 1].b, &scratch_);
    VCycle(d - 1);
    ProlongAdd(levels_[d - 1].n, levels_[d - 1].x, &level.x, &scratch_);
    for (int sweep = 0; sweep < kSmoothingSweeps; ++sweep) Smooth(d);
  }

  void FactorCoarsest() {
    const int64_t m = levels_[kCoarsestDepth].size();
    Eigen::MatrixXd dense(m, m);
    std::vector<float> e(m, 0.0f), column(m);
    for (int64_t i = 0; i < m; ++i) {
      e[i] = 1;
      Apply(kCoarsestDepth, e, &column);
      for (int64_t j = 0; j < m; ++j) dense(j, i) = column[j];
      e[i] = 0;
    }
    coarsest_ = std::make_unique<Eigen::LLT<Eigen::MatrixXd>>(dense);
  }

  ScreeningTerms screening_;
  std::vector<float> scratch_;  // Restrict's and ProlongAdd's partial results
  std::vector<Level> levels_;  // indexed by depth; entries below kCoarsestDepth unused
  std::unique_ptr<Eigen::LLT<Eigen::MatrixXd>> coarsest_;
};

double Dot(const std::vector<float>& a, const std::vector<float>& b) {
  double sum = 0;
  for (size_t i = 0; i < a.size(); ++i) sum += double(a[i]) * b[i];
  return sum;
}

}  // namespace

SolverReport SolveScreenedPoisson(int depth, const std::vector<ScreeningSample>& samples,
                                  const std::vector<float>& b, double tolerance, int max_iterations,
                                  std::vector<float>* x) {
  Multigrid multigrid(depth, samples);
  const size_t size = b.size();
  std::vector<float> r(size), z(size), p(size), q(size);
  multigrid.Apply(depth, *x, &q);
  for (size_t i = 0; i < size; ++i) r[i] = b[i] - q[i];
  const double b_norm = std::sqrt(Dot(b, b));
  SolverReport report;
  if (b_norm == 0) return report;
  multigrid.Precondition(r, &z);
  p = z;
  double rz = Dot(r, z);
  report.relative_residual = std::sqrt(Dot(r, r)) / b_norm;
  while (report.relative_residual > tolerance && report.iterations < max_iterations) {
    multigrid.Apply(depth, p, &q);
    const double pq = Dot(p, q);
    if (!(pq > 0)) break;  // converged to float precision: no descent direction left
    const float alpha = float(rz / pq);
    for (size_t i = 0; i < size; ++i) {
      (*x)[i] += alpha * p[i];
      r[i] -= alpha * q[i];
    }
    ++report.iterations;
    report.relative_residual = std::sqrt(Dot(r, r)) / b_norm;
    multigrid.Precondition(r, &z);
    const double rz_next = Dot(r, z);
    const float beta = float(rz_next / rz);
    rz = rz_next;
    for (size_t i = 0; i < size; ++i) p[i] = z[i] + beta * p[i];
  }
  return report;
}

void ProlongTrilinear(int coarse_depth, const std::vector<float>& coarse, std::vector<float>* fine) {
  const int64_t n = (int64_t(1) << (coarse_depth + 1)) + 1;
  fine->assign(n * n * n, 0.0f);
  std::vector<float> scratch;
  ProlongAdd((1 << coarse_depth) + 1, coarse, fine, &scratch);
}

}  // namespace graspsim
