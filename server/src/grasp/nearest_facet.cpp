#include "grasp/nearest_facet.h"

#include <algorithm>
#include <array>
#include <cstdint>
#include <cmath>
#include <limits>

#include <Eigen/Dense>

namespace graspsim::grasp {
namespace {

using Vec6 = Eigen::Matrix<double, 6, 1>;

struct Facet {
  std::array<int, 6> v;  // sorted vertex (wrench) indices
  Vec6 normal;           // unit, outward
  double offset;         // normal · x = offset on the facet; the polytope is below
};

// The plane through six wrenches, oriented so that `inside` is below it. False when they do not span a 5-flat.
// Modified Gram-Schmidt on the five differences, then the unit axis least inside their span, made orthogonal
// to them: ~300 flops, a fifth of a pivoting LU; the final facet is recomputed with the LU (ExactPlane).
bool Plane(const std::vector<Vec6>& w, const std::array<int, 6>& v, const Vec6& inside, double scale, Vec6* normal,
           double* offset) {
  Vec6 q[5];
  for (int k = 0; k < 5; ++k) {
    q[k] = w[v[k + 1]] - w[v[0]];
    for (int j = 0; j < k; ++j) q[k] -= q[k].dot(q[j]) * q[j];
    const double length = q[k].norm();
    if (length <= 1e-10 * scale) return false;
    q[k] /= length;
  }
  int axis = 0;
  double room = -1;
  for (int j = 0; j < 6; ++j) {
    double r = 1;
    for (const Vec6& b : q) r -= b(j) * b(j);
    if (r > room) room = r, axis = j;
  }
  Vec6 n = Vec6::Unit(axis);
  for (const Vec6& b : q) n -= b(axis) * b;
  for (const Vec6& b : q) n -= n.dot(b) * b;  // a second pass: orthogonal to rounding
  *normal = n.normalized();
  *offset = normal->dot(w[v[0]]);
  if (normal->dot(inside) > *offset) {
    *normal = -*normal;
    *offset = -*offset;
  }
  return true;
}

// The same plane from a full-pivoting LU's kernel: the most accurate offset, for the answer.
double ExactOffset(const std::vector<Vec6>& w, const std::array<int, 6>& v, const Vec6& inside, double fallback) {
  Eigen::Matrix<double, 5, 6> m;
  for (int k = 1; k < 6; ++k) m.row(k - 1) = (w[v[k]] - w[v[0]]).transpose();
  const Eigen::FullPivLU<Eigen::Matrix<double, 5, 6>> lu(m);
  if (lu.rank() < 5) return fallback;
  Vec6 normal = lu.kernel().col(0).normalized();
  double offset = normal.dot(w[v[0]]);
  if (normal.dot(inside) > offset) offset = -offset;
  return offset;
}

}  // namespace

NearestFacetResult NearestFacet(const std::vector<Wrench>& wrenches) {
  NearestFacetResult result;
  const int n = static_cast<int>(wrenches.size());
  if (n < 7) {
    result.degenerate = true;
    return result;
  }
  // Per-thread scratch: a planner thread scores thousands of grasps, and these would be its only allocations.
  thread_local std::vector<Vec6> w;
  thread_local std::vector<Vec6> basis;
  thread_local std::vector<Facet> facets;
  thread_local std::vector<uint64_t> ridges;
  w.resize(n);
  basis.clear();
  facets.clear();
  double scale = 0;
  for (int i = 0; i < n; ++i) {
    w[i] = Eigen::Map<const Vec6>(wrenches[i].data());
    scale = std::max(scale, w[i].norm());
  }
  const double tolerance = 1e-12 * std::max(scale, 1e-300);

  // A full-dimensional start: greedily the wrench farthest from the affine hull of those already taken.
  std::array<int, 7> simplex;
  simplex[0] = 0;
  for (int i = 1; i < n; ++i) {
    if ((w[i] - w[0]).norm() > (w[simplex[0]] - w[0]).norm()) simplex[0] = i;
  }
  for (int k = 1; k < 7; ++k) {
    double best = -1;
    Vec6 best_residual = Vec6::Zero();
    for (int i = 0; i < n; ++i) {
      Vec6 r = w[i] - w[simplex[0]];
      for (const Vec6& b : basis) r -= r.dot(b) * b;
      if (r.norm() > best) {
        best = r.norm();
        best_residual = r;
        simplex[k] = i;
      }
    }
    if (best <= 1e-9 * scale) {  // the wrenches do not span R^6
      result.degenerate = true;
      return result;
    }
    basis.push_back(best_residual / best);
  }
  Vec6 inside = Vec6::Zero();
  for (int i : simplex) inside += w[i];
  inside /= 7;

  for (int skip = 0; skip < 7; ++skip) {
    Facet f;
    int k = 0;
    for (int j = 0; j < 7; ++j) {
      if (j != skip) f.v[k++] = simplex[j];
    }
    std::sort(f.v.begin(), f.v.end());
    if (!Plane(w, f.v, inside, scale, &f.normal, &f.offset)) return result;
    facets.push_back(f);
  }

  // A ridge (five sorted wrench indices, each below 2^12) packed into one integer: sorting them finds the
  // horizon several times faster than sorting index arrays.
  if (n >= (1 << 12)) return result;  // never for a grasp (at most 4 contacts per link); qhull decides
  for (int iteration = 0; iteration <= n + 8; ++iteration) {
    int nearest = -1;
    for (int f = 0; f < static_cast<int>(facets.size()); ++f) {
      if (nearest < 0 || facets[f].offset < facets[nearest].offset) nearest = f;
    }
    if (nearest < 0) return result;
    const Vec6 u = facets[nearest].normal;
    int support = 0;
    double reach = -std::numeric_limits<double>::infinity();
    for (int i = 0; i < n; ++i) {
      const double h = u.dot(w[i]);
      if (h > reach) reach = h, support = i;
    }
    if (reach <= 0) {
      // Every wrench lies on or below the plane u·x = reach <= 0, which the origin is not below: the origin is
      // not strictly inside the hull, so no force closure, whatever the nearest facet turns out to be. Most
      // grasps that are not force closure stop here after a few iterations instead of building the hull's
      // whole near side.
      result.converged = true;
      result.distance = reach;
      return result;
    }
    if (reach <= facets[nearest].offset + tolerance) {  // nothing beyond: a facet of the hull
      result.converged = true;
      result.distance = ExactOffset(w, facets[nearest].v, inside, facets[nearest].offset);
      return result;
    }
    // Beneath-beyond: the facets that see the new wrench go (swapped out, so that only live facets are ever
    // scanned); their ridges seen once form the horizon.
    ridges.clear();
    for (size_t f = 0; f < facets.size();) {
      const Facet& facet = facets[f];
      if (facet.normal.dot(w[support]) <= facet.offset + tolerance) {
        ++f;
        continue;
      }
      for (int skip = 0; skip < 6; ++skip) {
        uint64_t key = 0;
        for (int j = 0; j < 6; ++j) {
          if (j != skip) key = (key << 12) | static_cast<uint64_t>(facet.v[j]);
        }
        ridges.push_back(key);
      }
      facets[f] = facets.back();
      facets.pop_back();
    }
    std::sort(ridges.begin(), ridges.end());
    for (size_t r = 0; r < ridges.size();) {
      size_t same = r + 1;
      while (same < ridges.size() && ridges[same] == ridges[r]) ++same;
      if (same - r == 1) {  // on the horizon
        Facet f;
        for (int j = 4; j >= 0; --j) f.v[4 - j] = static_cast<int>((ridges[r] >> (12 * j)) & 0xfff);
        f.v[5] = support;
        std::sort(f.v.begin(), f.v.end());
        if (Plane(w, f.v, inside, scale, &f.normal, &f.offset)) {
          facets.push_back(f);
        }
      }
      r = same;
    }
  }
  return result;
}

}  // namespace graspsim::grasp
