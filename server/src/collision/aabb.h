// Axis-aligned boxes: the broad phase of every collision and ray query (body bounds, sample blocks, pad foam).
#pragma once

#include <limits>

#include "core/math.h"

namespace graspsim::collision {

// An axis-aligned box, m. Empty when lo > hi on any axis.
struct Aabb {
  Vec3 lo = Vec3::Constant(std::numeric_limits<double>::infinity());
  Vec3 hi = Vec3::Constant(-std::numeric_limits<double>::infinity());

  bool Empty() const { return (lo.array() > hi.array()).any(); }
  void Add(const Vec3& p) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  void Add(const Aabb& b) {
    lo = lo.cwiseMin(b.lo);
    hi = hi.cwiseMax(b.hi);
  }
  // Coefficient by coefficient: cheaper than Eigen's all() in the per-sample and per-segment loops.
  bool Contains(const Vec3& p) const {
    return p.x() >= lo.x() && p.x() <= hi.x() && p.y() >= lo.y() && p.y() <= hi.y() && p.z() >= lo.z() &&
           p.z() <= hi.z();
  }
  bool Overlaps(const Aabb& b) const {
    return (lo.array() <= b.hi.array()).all() && (b.lo.array() <= hi.array()).all();
  }
};

// The box that holds `box` after the rigid map x -> rotation * x + translation.
inline Aabb TransformAabb(const Aabb& box, const Mat3& rotation, const Vec3& translation) {
  if (box.Empty()) return box;
  const Vec3 centre = rotation * (0.5 * (box.lo + box.hi)) + translation;
  const Vec3 extent = rotation.cwiseAbs() * (0.5 * (box.hi - box.lo));
  return {centre - extent, centre + extent};
}

}  // namespace graspsim::collision
