// SegmentEntries (segment_box.h): SegmentMeetsBox's arithmetic, in the same order, with its branches turned into
// selects and its early exits into one test at the end (lo only grows and hi only shrinks, so an axis that empties
// the interval keeps it empty). The selects are written as std::min/std::max spell them ((b < a) ? b : a), the form
// the compiler maps onto SIMD min/max with the same answers. The direction is shared, so the parallel-slab branch
// is chosen per run: a tilted direction (the usual case) needs none. Compiled at -O3 (tactile/CMakeLists.txt).
#include "tactile/segment_box.h"

#include <limits>

namespace graspsim {
namespace {

constexpr double kMiss = std::numeric_limits<double>::infinity();

// kParallel: some component of the direction is zero; the segment must then lie within that slab.
template <bool kParallel>
inline __attribute__((always_inline)) void Entries(const PointColumns& points, size_t count, const Mat3& rotation, const Vec3& translation,
             const SegmentDirection& direction, double length, const collision::Aabb& box, double* entry) {
  const double r00 = rotation(0, 0), r01 = rotation(0, 1), r02 = rotation(0, 2);
  const double r10 = rotation(1, 0), r11 = rotation(1, 1), r12 = rotation(1, 2);
  const double r20 = rotation(2, 0), r21 = rotation(2, 1), r22 = rotation(2, 2);
  const double tx = translation.x(), ty = translation.y(), tz = translation.z();
  const bool parallel[3] = {direction.d[0] == 0, direction.d[1] == 0, direction.d[2] == 0};
  const double inv[3] = {direction.inverse[0], direction.inverse[1], direction.inverse[2]};
  const double blo[3] = {box.lo[0], box.lo[1], box.lo[2]}, bhi[3] = {box.hi[0], box.hi[1], box.hi[2]};
  const double* px = points.x;
  const double* py = points.y;
  const double* pz = points.z;
  for (size_t i = 0; i < count; ++i) {
    // Eigen's lazy 3 × 3 product (SSE2) sums rows 0 and 1 as one packet, left to right, and row 2 as a scalar
    // reduction, (a + (b + c)): the same order here keeps the entries bit for bit those of the scalar form.
    const double o[3] = {r00 * px[i] + r01 * py[i] + r02 * pz[i] + tx, r10 * px[i] + r11 * py[i] + r12 * pz[i] + ty,
                         r20 * px[i] + (r21 * py[i] + r22 * pz[i]) + tz};
    double lo = 0, hi = length;
    bool outside = false;  // beside a slab the segment runs parallel to
    for (int k = 0; k < 3; ++k) {
      const double t0 = (blo[k] - o[k]) * inv[k], t1 = (bhi[k] - o[k]) * inv[k];
      const double near = t1 < t0 ? t1 : t0, far = t1 < t0 ? t0 : t1;  // if (t0 > t1) swap
      if constexpr (kParallel) {
        lo = !parallel[k] && lo < near ? near : lo;
        hi = !parallel[k] && far < hi ? far : hi;
        outside = outside | (parallel[k] & ((o[k] < blo[k]) | (o[k] > bhi[k])));
      } else {
        lo = lo < near ? near : lo;  // std::max(lo, near)
        hi = far < hi ? far : hi;    // std::min(hi, far)
      }
    }
    entry[i] = outside || lo > hi ? kMiss : lo;
  }
}

}  // namespace

// On x86-64 with GCC, cloned for AVX2 (four lanes instead of SSE2's two) and picked at load time by the CPU. Not
// for FMA: contracted products would round differently from SegmentMeetsBox.
#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__)
__attribute__((target_clones("avx2", "default")))
#endif
void SegmentEntries(const PointColumns& points, size_t count, const Mat3& rotation, const Vec3& translation,
                    const SegmentDirection& direction, double length, const collision::Aabb& box, double* entry) {
  if ((direction.d.array() != 0).all()) {
    Entries<false>(points, count, rotation, translation, direction, length, box, entry);
  } else {
    Entries<true>(points, count, rotation, translation, direction, length, box, entry);
  }
}

}  // namespace graspsim
