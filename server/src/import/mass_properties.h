// Mass properties of solid geometry at a uniform density: what MuJoCo's compiler computes for inertiafromgeom and
// what a robot file's missing or unphysical inertial is repaired from (docs/import.md).
//
// Closed forms for the primitives (box m(b²+c²)/12 ..., sphere 2/5 m r², cylinder m r²/2 about its axis and
// m(3r²+l²)/12 across it); a triangle mesh by the divergence theorem over the signed tetrahedra its triangles span
// with the origin (Mirtich's integrals in the covariance form: exact for a closed, consistently oriented mesh;
// a mesh wound inside out counts with its absolute volume). Parts add with the parallel-axis theorem.
#pragma once

#include <vector>

#include "world/model.h"

namespace graspsim {

// Volume (m^3), centroid (m) and the second moment about the centroid per unit density (m^5), in the frame of
// the geometry's own origin-applied body frame.
struct SolidVolume {
  double volume = 0;
  Vec3 centroid = Vec3::Zero();
  Mat3 inertia_per_density = Mat3::Zero();
};

// One geometry, in the body frame (its origin applied). A mesh with no enclosed volume (open or flat) has volume 0.
SolidVolume VolumeOf(const Geometry& geometry);

// The union of the geometries as one solid of `density` kg/m^3 (overlaps counted twice, as MuJoCo does): mass,
// centre of mass and inertia about it in the body frame. Mass 0 when nothing has volume.
Inertial SolidMassProperties(const std::vector<Geometry>& geometry, double density);

}  // namespace graspsim
