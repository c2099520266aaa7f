// Private to collision/: exact signed distances of the primitives, inline because they run once per sample in
// the innermost loop. Each takes a point in the geometry frame and returns the penetration depth: > 0 inside
// (distance to the nearest surface point), < 0 outside (minus the distance to the shape). *normal is the unit
// outward normal of the surface at that nearest point. Ties (a point equally far from two faces) go to the lower
// axis, so the answer never depends on anything but the point.
#pragma once

#include <cmath>

#include "core/math.h"

namespace graspsim::collision {

// A box centred on its frame with half edge lengths `half`.
inline double BoxDepth(const Vec3& half, const Vec3& p, Vec3* normal) {
  const Vec3 q = p.cwiseAbs() - half;  // per axis: > 0 means beyond that pair of faces
  if (q.x() <= 0 && q.y() <= 0 && q.z() <= 0) {
    int axis = 0;  // the nearest face is the one with the least negative q
    if (q.y() > q[axis]) axis = 1;
    if (q.z() > q[axis]) axis = 2;
    normal->setZero();
    (*normal)[axis] = p[axis] < 0 ? -1 : 1;
    return -q[axis];
  }
  const Vec3 offset = p - p.cwiseMax(-half).cwiseMin(half);  // from the closest point of the box; nonzero here
  const double distance = offset.norm();
  *normal = offset / distance;
  return -distance;
}

// BoxDepth for a point inside the box, with the normal of the nearest face among `faces` (bit 2 axis + 1 for the
// + face, 2 axis for the − face); the plain BoxDepth when the point is outside or no face is allowed. The depth
// stays the distance to the nearest face of all, so it grows from zero as a point crosses any face: a point
// entering through a face not in `faces` is pushed along an allowed normal, gently at first.
inline double BoxDepthThrough(const Vec3& half, const Vec3& p, unsigned faces, Vec3* normal) {
  const double plain = BoxDepth(half, p, normal);
  if (plain <= 0 || faces == 0 || faces == 0x3f) return plain;
  double best = INFINITY;
  for (int axis = 0; axis < 3; ++axis) {
    for (int positive = 0; positive < 2; ++positive) {
      if (!(faces >> (2 * axis + positive) & 1)) continue;
      const double depth = half[axis] - (positive ? p[axis] : -p[axis]);
      if (depth < best) {
        best = depth;
        normal->setZero();
        (*normal)[axis] = positive ? 1 : -1;
      }
    }
  }
  return plain;
}

// A sphere of `radius` centred on its frame.
inline double SphereDepth(double radius, const Vec3& p, Vec3* normal) {
  const double distance = p.norm();
  *normal = distance > 0 ? Vec3(p / distance) : Vec3::UnitZ();  // the centre: any direction is nearest
  return radius - distance;
}

// A solid cylinder of `radius` along z, centred, from z = -half_length to half_length (caps included).
inline double CylinderDepth(double radius, double half_length, const Vec3& p, Vec3* normal) {
  const double rho = std::hypot(p.x(), p.y());
  const Vec3 radial = rho > 0 ? Vec3(p.x() / rho, p.y() / rho, 0) : Vec3::UnitX();
  const Vec3 axial(0, 0, p.z() < 0 ? -1 : 1);
  const double dr = rho - radius;                // > 0 outside the side
  const double dz = std::abs(p.z()) - half_length;  // > 0 beyond a cap
  if (dr <= 0 && dz <= 0) {
    *normal = dr >= dz ? radial : axial;  // the nearer of side and cap
    return -std::max(dr, dz);
  }
  if (dr > 0 && dz > 0) {  // nearest the rim circle
    const double distance = std::hypot(dr, dz);
    *normal = (dr * radial + dz * axial) / distance;
    return -distance;
  }
  *normal = dr > 0 ? radial : axial;
  return -std::max(dr, dz);
}

}  // namespace graspsim::collision
