// The slab test of a pad's segments against a box, one segment (SegmentMeetsBox) or a run of elements sharing a
// direction at once (SegmentEntries: plain arrays, no branch per element, so the compiler keeps it in SIMD lanes).
// A flat pad's 84 elements share their normal: the work cycle casts them against the cube every step
// (tactile/ray_caster.cpp). Both give the same answers bit for bit (tests/cpp/tactile/segment_box_test.cpp).
#pragma once

#include <algorithm>
#include <cstddef>
#include <utility>

#include "collision/aabb.h"
#include "core/math.h"

namespace graspsim {

// A segment direction d with its componentwise inverse (0 where d is 0): computed once per shared normal.
struct SegmentDirection {
  Vec3 d = Vec3::Zero(), inverse = Vec3::Zero();
  void Set(const Vec3& direction) {
    d = direction;
    for (int k = 0; k < 3; ++k) inverse[k] = d[k] == 0 ? 0.0 : 1 / d[k];
  }
};

// Does the segment o + t d, 0 <= t <= length, meet the box? (slab test) *entry: the smallest such t.
inline bool SegmentMeetsBox(const Vec3& o, const SegmentDirection& direction, double length,
                            const collision::Aabb& box, double* entry = nullptr) {
  double lo = 0, hi = length;
  for (int k = 0; k < 3; ++k) {
    if (direction.d[k] == 0) {
      if (o[k] < box.lo[k] || o[k] > box.hi[k]) return false;
      continue;
    }
    double t0 = (box.lo[k] - o[k]) * direction.inverse[k], t1 = (box.hi[k] - o[k]) * direction.inverse[k];
    if (t0 > t1) std::swap(t0, t1);
    lo = std::max(lo, t0);
    hi = std::min(hi, t1);
    if (lo > hi) return false;
  }
  if (entry != nullptr) *entry = lo;
  return true;
}

// Points given as one array per coordinate (x[i], y[i], z[i]).
struct PointColumns {
  const double *x = nullptr, *y = nullptr, *z = nullptr;
};

// For i in [0, count): the segment from o_i = rotation p_i + translation (p_i from `points`, the product summed in
// Eigen's order) along `direction`: entry[i] = SegmentMeetsBox's *entry where it meets the box, +infinity where not.
void SegmentEntries(const PointColumns& points, size_t count, const Mat3& rotation, const Vec3& translation,
                    const SegmentDirection& direction, double length, const collision::Aabb& box, double* entry);

}  // namespace graspsim
