#include "perception/poisson.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>

#include "core/error.h"
#include "core/format.h"
#include "core/validate.h"
#include "perception/cloud_filters.h"
#include "perception/marching_cubes.h"
#include "perception/screened_poisson_solver.h"

namespace graspsim {
namespace {

using Clock = std::chrono::steady_clock;

// Grids up to 33³ nodes are solved whole (multigrid CG: a few ms); finer ones only near the samples.
constexpr int kFullSolveDepth = 5;
// Band half-width beyond the splat's reach (cells): b is zero past the reach, and one more cell leaves the
// deviation unchanged (0.0050 mm on the 39k sphere at depth 7, against 0.0049 mm with 3) for fewer iterations.
constexpr int kBandMargin = 1;

double MsSince(Clock::time_point start) {
  return std::chrono::duration<double, std::milli>(Clock::now() - start).count();
}

void CheckRange(const std::string& field, double value, double lo, double hi, bool lo_open = false) {
  CheckFinite(field, value);
  if (value < lo || value > hi || (lo_open && value == lo)) {
    ThrowInvalidArgument(field + ": " + FormatNumber(value) + " is outside " + (lo_open ? "(" : "") +
                         FormatNumber(lo) + ".." + FormatNumber(hi) + (lo_open ? "]" : ""));
  }
}

void Validate(const std::vector<Vec3>& points, const std::vector<Vec3>& normals, const PoissonParams& params) {
  if (params.depth < 5 || params.depth > 8) {
    ThrowInvalidArgument("depth: " + std::to_string(params.depth) + " is outside 5..8");
  }
  CheckRange("screening", params.screening, 0, 1e4, true);
  CheckRange("scale", params.scale, 1.05, 4);
  CheckRange("tolerance", params.tolerance, 0, 0.1, true);
  CheckRange("refine_limit", params.refine_limit, 0, 4);
  if (params.max_iterations < 1 || params.max_iterations > 1000) {
    ThrowInvalidArgument("max_iterations: " + std::to_string(params.max_iterations) + " is outside 1..1000");
  }
  if (points.empty()) ThrowInvalidArgument("points: the cloud is empty");
  if (normals.size() != points.size()) {
    ThrowInvalidArgument("normals: " + std::to_string(normals.size()) + " normals for " +
                         std::to_string(points.size()) + " points");
  }
  for (size_t i = 0; i < points.size(); ++i) {
    // The field's name is built only for a bad value (a string per point cost ~0.5 ms on 5k points).
    if (!points[i].allFinite()) CheckFinite("points[" + std::to_string(i) + "]", points[i]);
    if (!normals[i].allFinite()) CheckFinite("normals[" + std::to_string(i) + "]", normals[i]);
    if (normals[i].squaredNorm() == 0) ThrowInvalidArgument("normals[" + std::to_string(i) + "]: zero length");
  }
  const Vec3 spread = SpreadEigenvalues(points);
  if (!(spread[2] > 0)) {
    ThrowInvalidArgument("points: all " + std::to_string(points.size()) + " points coincide");
  }
  // A surface needs two directions of spread; a line (or a single point) bounds no volume.
  if (spread[1] <= 1e-12 * spread[2]) {
    ThrowInvalidArgument("points: all " + std::to_string(points.size()) +
                         " points lie on a line (spread across it " +
                         FormatNumber(std::sqrt(std::max(spread[1], 0.0) / double(points.size()))) + " m)");
  }
}

struct Grid {
  int depth = 0;
  int n = 0;         // nodes per side
  Vec3 origin;
  double h = 0;      // cell size, m
  Vec3 ToGrid(const Vec3& p) const { return (p - origin) / h; }
  int64_t Index(int i, int j, int k) const { return (int64_t(k) * n + j) * n + i; }
};

Grid MakeGrid(const std::vector<Vec3>& points, const PoissonParams& params) {
  Vec3 lo = points.front(), hi = points.front();
  for (const Vec3& p : points) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  Grid grid;
  grid.depth = params.depth;
  grid.n = (1 << params.depth) + 1;
  const double side = (hi - lo).maxCoeff() * params.scale;
  grid.h = side / (1 << params.depth);
  grid.origin = (lo + hi) / 2 - Vec3::Constant(side / 2);
  return grid;
}

// The same cube with 2^depth cells per side.
Grid Coarsened(const Grid& fine, int depth) {
  Grid grid = fine;
  grid.depth = depth;
  grid.n = (1 << depth) + 1;
  grid.h = fine.h * double(1 << (fine.depth - depth));
  return grid;
}

// Nodes within `margin` cells of a sample's cell: where the splat put b ≠ 0 (reach ≤ margin − 1) and where the
// indicator changes on the scale of this grid.
std::vector<uint8_t> BandAround(const std::vector<ScreeningSample>& samples, const Grid& grid, int margin) {
  std::vector<uint8_t> band(int64_t(grid.n) * grid.n * grid.n, 0);
  const int64_t layer = int64_t(grid.n) * grid.n;
  for (const ScreeningSample& s : samples) {
    const int i0 = int(s.base % grid.n), j0 = int(s.base / grid.n % grid.n), k0 = int(s.base / layer);
    const int ilo = std::max(0, i0 - margin), ihi = std::min(grid.n - 1, i0 + 1 + margin);
    for (int k = std::max(0, k0 - margin); k <= std::min(grid.n - 1, k0 + 1 + margin); ++k) {
      for (int j = std::max(0, j0 - margin); j <= std::min(grid.n - 1, j0 + 1 + margin); ++j) {
        std::fill_n(band.begin() + grid.Index(ilo, j, k), ihi - ilo + 1, uint8_t(1));
      }
    }
  }
  return band;
}

// Surface area the samples cover, m²: cells they occupy on the finest grid at which a cell holds ≥ 4 samples on
// average (so few cells the surface crosses are empty), each worth h² / 1.5 (the mean area of a randomly
// oriented plane in a unit cube is 1 / 1.5 of the cubes it crosses).
double EstimateArea(const std::vector<Vec3>& points, double total_count, const Grid& grid) {
  std::vector<int64_t> cells(points.size());
  double area = 0;
  for (int coarsen = 0; coarsen <= grid.depth; ++coarsen) {
    const double h = grid.h * (1 << coarsen);
    const int64_t n = int64_t(1) << (grid.depth - coarsen);
    for (size_t i = 0; i < points.size(); ++i) {
      const Vec3 u = (points[i] - grid.origin) / h;
      const int64_t x = std::clamp<int64_t>(int64_t(u.x()), 0, n - 1), y = std::clamp<int64_t>(int64_t(u.y()), 0, n - 1),
                    z = std::clamp<int64_t>(int64_t(u.z()), 0, n - 1);
      cells[i] = (z * n + y) * n + x;
    }
    std::sort(cells.begin(), cells.end());
    const double occupied = double(std::unique(cells.begin(), cells.end()) - cells.begin());
    area = occupied * h * h / 1.5;
    if (total_count >= 4 * occupied) break;
  }
  return area;
}

// Stage 2: the right-hand side b = Dᵀ V of the normal equations, straight from the samples (normals: each merged
// sample's mean of unit normals, MergedSamples below). Each sample carries its normal's component a into the
// a-edges around it (tent weights, centred half a cell along a from the edges' lower nodes); an a-edge from node m
// to m + e_a with value v adds v to b at m + e_a and −v at m. So b is nonzero only within the kernel's reach of the
// samples, and the field V itself is never stored.
std::vector<float> SplatNormals(const std::vector<Vec3>& points, const std::vector<Vec3>& normals, const Grid& grid,
                                double sample_area, int* reach_out) {
  const int n = grid.n;
  const double half_width = std::clamp(std::sqrt(sample_area) / grid.h, 2.0, 16.0);  // cells
  const int reach = int(std::ceil(half_width));
  *reach_out = reach;
  const double jump = sample_area / (grid.h * grid.h);  // edges a sample's patch crosses, per unit normal
  const int64_t stride[3] = {1, n, int64_t(n) * n};
  std::vector<float> b(int64_t(n) * n * n, 0.0f);
  // Per axis, the tent weights about the sample (nodes, for the components across that axis) and about it shifted
  // half a cell back (edges along it): six lists per sample instead of nine, fixed arrays (reach ≤ 16).
  struct Weights {
    int first = 0, count = 0;
    double w[32];
  };
  const auto tent = [&](double c, int last, Weights* out) {
    out->first = std::max(0, int(std::floor(c)) - reach + 1);
    const int end = std::min(last, int(std::floor(c)) + reach);
    out->count = std::max(0, end - out->first + 1);
    double sum = 0;
    for (int m = 0; m < out->count; ++m) {
      out->w[m] = std::max(0.0, 1.0 - std::abs(out->first + m - c) / half_width);
      sum += out->w[m];
    }
    for (int m = 0; m < out->count; ++m) out->w[m] /= sum;
  };
  Weights node[3], edge[3];
  for (size_t s = 0; s < points.size(); ++s) {
    const Vec3 u = grid.ToGrid(points[s]);
    const Vec3& normal = normals[s];
    for (int axis = 0; axis < 3; ++axis) {
      tent(u[axis], n - 1, &node[axis]);
      tent(u[axis] - 0.5, n - 2, &edge[axis]);
    }
    for (int a = 0; a < 3; ++a) {
      const Weights& wx = a == 0 ? edge[0] : node[0];
      const Weights& wy = a == 1 ? edge[1] : node[1];
      const Weights& wz = a == 2 ? edge[2] : node[2];
      const double amount = normal[a] * jump;
      for (int k = 0; k < wz.count; ++k) {
        for (int j = 0; j < wy.count; ++j) {
          const double wjk = amount * wz.w[k] * wy.w[j];
          float* row = b.data() + grid.Index(wx.first, wy.first + j, wz.first + k);
          for (int i = 0; i < wx.count; ++i) {
            const float v = float(wjk * wx.w[i]);
            row[i] -= v;
            row[i + stride[a]] += v;
          }
        }
      }
    }
  }
  return b;
}

ScreeningSample Sample(const Vec3& point, const Grid& grid, double sqrt_beta) {
  const Vec3 u = grid.ToGrid(point);
  int base[3];
  double t[3];
  for (int a = 0; a < 3; ++a) {
    base[a] = std::clamp(int(std::floor(u[a])), 0, grid.n - 2);
    t[a] = u[a] - base[a];
  }
  ScreeningSample sample;
  sample.base = grid.Index(base[0], base[1], base[2]);
  for (int c = 0; c < 8; ++c) {
    const double w = ((c & 1) ? t[0] : 1 - t[0]) * ((c >> 1 & 1) ? t[1] : 1 - t[1]) * ((c >> 2 & 1) ? t[2] : 1 - t[2]);
    sample.weight[c] = float(w * sqrt_beta);
  }
  return sample;
}

// Stage 4: χ at each sample (the screening weights divided back out), averaged.
double IsoValue(const std::vector<ScreeningSample>& samples, const std::vector<float>& chi, const Grid& grid) {
  double sum = 0;
  for (const ScreeningSample& s : samples) {
    double value = 0, weight = 0;
    for (int c = 0; c < 8; ++c) {
      const int64_t at = s.base + (c & 1) + int64_t(c >> 1 & 1) * grid.n + int64_t(c >> 2 & 1) * grid.n * grid.n;
      value += double(s.weight[c]) * chi[at];
      weight += s.weight[c];
    }
    sum += weight > 0 ? value / weight : 0;
  }
  return sum / double(samples.size());
}

// Nodes farther than `margin` outside the samples' bounding box count as outside. The grid reaches (scale − 1)/2
// of the extent beyond the samples so that their surface is never cut; but where a one-sided cloud leaves the
// indicator's inside open, the iso-surface balloons into that room, away from every sample (issue 22: more than
// half of the completions' reverse deviation). Clipped here, the surface closes flat at the box instead: still
// closed, since this only moves the border inwards.
void ClipToSamples(const Grid& grid, const std::vector<Vec3>& points, double margin, float iso,
                   std::vector<float>* chi) {
  Vec3 lo = points.front(), hi = points.front();
  for (const Vec3& p : points) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  const Eigen::Vector3d first = (grid.ToGrid(lo - Vec3::Constant(margin))).array().ceil();
  const Eigen::Vector3d last = (grid.ToGrid(hi + Vec3::Constant(margin))).array().floor();
  const int n = grid.n;
  for (int k = 0; k < n; ++k) {
    for (int j = 0; j < n; ++j) {
      for (int i = 0; i < n; ++i) {
        if (i >= first.x() && i <= last.x() && j >= first.y() && j <= last.y() && k >= first.z() && k <= last.z()) {
          continue;
        }
        float& v = (*chi)[grid.Index(i, j, k)];
        v = std::max(v, iso);
      }
    }
  }
}

// The samples merged per cell of the finest grid, as Kazhdan & Hoppe merge the samples that fall in one leaf node:
// one sample per occupied cell, at the mean position of its samples with the mean of their unit normals. A dense
// camera cloud (39k points, their mirror images and the table cap: 94k) then costs the splat and the screening
// what its ~2k occupied cells cost, and a cloud sparser than the cells passes unchanged (its normals made unit).
// Each cell counts once, however many samples it holds: the indicator's jump follows the samples' density, and a
// depth camera's density follows the incidence (a face turned to it holds several times the points per area of a
// grazing one, and the table cap as many as the densest face), which shifted the surface where the density
// changes (issue 22: 0.3 mm of the completions' reverse deviation; `PoissonTest.UnevenSamplingGivesTheEvenSurface`).
// Kazhdan's density estimate does the same at the scale of a kernel; here it is the finest cell's.
struct MergedSamples {
  std::vector<Vec3> points, normals;
};

MergedSamples MergePerCell(const std::vector<Vec3>& points, const std::vector<Vec3>& normals, const Grid& finest) {
  std::vector<uint32_t> group;
  const size_t groups = VoxelGroups(points, finest.h, finest.origin, &group);
  MergedSamples merged;
  merged.points.assign(groups, Vec3::Zero());
  merged.normals.assign(groups, Vec3::Zero());
  std::vector<uint32_t> counts(groups, 0);
  for (size_t i = 0; i < points.size(); ++i) {
    merged.points[group[i]] += points[i];
    // Unit already within rounding (the shape pipeline's normals): the square root and division skipped.
    const double length_sq = normals[i].squaredNorm();
    merged.normals[group[i]] +=
        std::abs(length_sq - 1) < 1e-12 ? normals[i] : Vec3(normals[i] / std::sqrt(length_sq));
    ++counts[group[i]];
  }
  for (size_t g = 0; g < groups; ++g) {
    merged.points[g] /= double(counts[g]);
    merged.normals[g] /= double(counts[g]);
  }
  return merged;
}

// Only the nodes inside (χ < iso) are asked: clearing an outside node would change nothing.
void ClearKnownOutside(const Grid& grid, const KnownOutside& known_outside, float iso, std::vector<float>* chi) {
  const int n = grid.n;
  for (int k = 0; k < n; ++k) {
    for (int j = 0; j < n; ++j) {
      for (int i = 0; i < n; ++i) {
        float& v = (*chi)[grid.Index(i, j, k)];
        if (v < iso && known_outside(grid.origin + grid.h * Vec3(i, j, k))) v = iso;
      }
    }
  }
}

void CloseAtBorder(const Grid& grid, float iso, std::vector<float>* chi) {
  const int n = grid.n;
  for (int k = 0; k < n; ++k) {
    for (int j = 0; j < n; ++j) {
      const bool face = k == 0 || j == 0 || k == n - 1 || j == n - 1;
      for (int i = 0; i < n; i += (face ? 1 : n - 1)) {
        float& v = (*chi)[grid.Index(i, j, k)];
        v = std::max(v, iso);
      }
    }
  }
}

}  // namespace

PoissonResult ReconstructSurface(const std::vector<Vec3>& points, const std::vector<Vec3>& normals,
                                 const PoissonParams& params, const KnownOutside& known_outside) {
  Validate(points, normals, params);
  PoissonResult result;
  PoissonStats& stats = result.stats;

  // Stages 1–3, coarse to fine: a full solve on a grid of at most kFullSolveDepth, then each finer level
  // corrected in a band around the samples only (RefineInBand): far from them χ is flat and the coarse grid
  // already has it. Per level: grid, splat and samples (timed as "splat"), then the solve.
  const Grid finest = MakeGrid(points, params);
  stats.cell_size = finest.h;
  auto start = Clock::now();
  const MergedSamples merged = MergePerCell(points, normals, finest);
  stats.sample_area = EstimateArea(merged.points, double(points.size()), finest) / double(merged.points.size());
  stats.ms_grid_splat += MsSince(start);
  std::vector<float> chi;
  std::vector<ScreeningSample> samples;
  const int first = std::min(params.depth, kFullSolveDepth);
  for (int depth = first; depth <= params.depth; ++depth) {
    start = Clock::now();
    const Grid grid = Coarsened(finest, depth);
    // A level too fine for the samples is only interpolated: no right-hand side needed.
    const bool too_fine = depth > first && grid.h < params.refine_limit * std::sqrt(stats.sample_area);
    int reach = 1;
    const std::vector<float> b = too_fine ? std::vector<float>()
                                          : SplatNormals(merged.points, merged.normals, grid, stats.sample_area,
                                                         &reach);
    // β = α a / h²: the screening of a patch does not depend on how densely it is sampled (Kazhdan & Hoppe,
    // eq. 3), nor on the level (χ keeps its unit jump on every grid).
    const double sqrt_beta = std::sqrt(params.screening * stats.sample_area / (grid.h * grid.h));
    samples.clear();
    samples.reserve(merged.points.size());
    for (size_t i = 0; i < merged.points.size(); ++i) {
      samples.push_back(Sample(merged.points[i], grid, sqrt_beta));
    }
    stats.ms_grid_splat += MsSince(start);

    start = Clock::now();
    SolverReport report;
    if (too_fine) {
      std::vector<float> coarse;
      coarse.swap(chi);
      ProlongTrilinear(depth - 1, coarse, &chi);
    } else if (depth == first) {
      chi.assign(b.size(), 0.0f);
      report = SolveScreenedPoisson(depth, samples, b, params.tolerance, params.max_iterations, &chi);
    } else {
      std::vector<float> coarse;
      coarse.swap(chi);
      ProlongTrilinear(depth - 1, coarse, &chi);
      report = RefineInBand(depth, BandAround(samples, grid, reach + kBandMargin), samples, b, params.tolerance,
                            params.max_iterations, &chi);
    }
    if (!too_fine) {
      stats.solved_depth = depth;
      stats.solver_iterations += report.iterations;
      stats.solver_relative_residual = report.relative_residual;
    }
    stats.ms_solve += MsSince(start);
  }
  const Grid& grid = finest;

  start = Clock::now();
  stats.iso_value = IsoValue(samples, chi, grid);
  stats.ms_iso = MsSince(start);

  start = Clock::now();
  // The border counts as outside: where the indicator's inside reaches it (an open, one-sided cloud can leak
  // there) the surface closes in the last cell instead of leaving a hole.
  CloseAtBorder(grid, float(stats.iso_value), &chi);
  if (params.clip_cells >= 0) ClipToSamples(grid, points, params.clip_cells * grid.h, float(stats.iso_value), &chi);
  if (known_outside) ClearKnownOutside(grid, known_outside, float(stats.iso_value), &chi);
  GridSamples view;
  view.nodes = Eigen::Vector3i::Constant(grid.n);
  view.origin = grid.origin;
  view.spacing = grid.h;
  view.values = chi.data();
  result.mesh = ExtractIsoSurface(view, float(stats.iso_value));
  stats.ms_extract = MsSince(start);
  return result;
}

}  // namespace graspsim
