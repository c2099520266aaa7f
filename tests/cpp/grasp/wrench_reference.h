// An independent float64 reference for the Ferrari-Canny ε: every 6-subset of the wrenches that spans a
// hyperplane with all wrenches on one side is a facet's plane (or lies in one); ε is the smallest distance of
// the origin to such a plane, 0 when the origin is not strictly inside all of them. Brute force, no qhull:
// C(n, 6) subsets, fine for the few dozen wrenches of a test grasp.
#pragma once

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include <Eigen/Dense>

#include "grasp/quality.h"

namespace graspsim::grasp::testing {

inline double ReferenceEpsilon(const std::vector<Wrench>& wrenches) {
  using Vec6 = Eigen::Matrix<double, 6, 1>;
  const int n = static_cast<int>(wrenches.size());
  std::vector<Vec6> w(n);
  double scale = 0;
  for (int i = 0; i < n; ++i) {
    w[i] = Eigen::Map<const Vec6>(wrenches[i].data());
    scale = std::max(scale, w[i].norm());
  }
  const double tolerance = 1e-11 * scale;
  double best = std::numeric_limits<double>::infinity();
  bool found = false;
  int idx[6];
  for (int k = 0; k < 6; ++k) idx[k] = k;
  while (n >= 6) {
    Eigen::Matrix<double, 5, 6> m;
    for (int k = 1; k < 6; ++k) m.row(k - 1) = (w[idx[k]] - w[idx[0]]).transpose();
    const Eigen::FullPivLU<Eigen::Matrix<double, 5, 6>> lu(m);
    if (lu.rank() == 5) {  // the five differences are independent: one hyperplane through the six
      Vec6 normal = lu.kernel().col(0).normalized();
      double offset = normal.dot(w[idx[0]]);
      bool below = false, above = false;  // some wrench strictly below / above the plane
      for (const Vec6& p : w) {
        const double d = normal.dot(p) - offset;
        below = below || d < -tolerance;
        above = above || d > tolerance;
        if (below && above) break;  // not a supporting plane
      }
      if (!(below && above)) {
        if (above) {  // orient so that every wrench is below it
          normal = -normal;
          offset = -offset;
        }
        best = std::min(best, offset);  // signed distance of the origin below the plane
        found = true;
      }
    }
    int k = 5;  // next combination
    while (k >= 0 && idx[k] == n - 6 + k) --k;
    if (k < 0) break;
    ++idx[k];
    for (int j = k + 1; j < 6; ++j) idx[j] = idx[j - 1] + 1;
  }
  return found && best > 0 ? best : 0.0;
}

}  // namespace graspsim::grasp::testing
