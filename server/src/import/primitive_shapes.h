// The shapes of robot files that graspsim has no primitive for, built from its own (URDF, MJCF and SDF loaders): a
// capsule as a cylinder and two spheres, an ellipsoid as a triangle mesh (a subdivided icosahedron), a plane as a
// thin box below it. Internal to import/.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "core/math.h"
#include "core/mesh.h"
#include "world/model.h"

namespace graspsim::import {

// Thickness of the box a <plane> becomes: the plane is its top face.
constexpr double kPlaneThickness = 0.1;  // m

// A capsule of `radius` whose cylindrical part has `length`, along z of `origin`: cylinder + 2 spheres.
std::vector<Geometry> CapsuleGeometries(double radius, double length, const Pose& origin);

// An ellipsoid with semi-axes `radii` along x, y, z of its frame: a closed mesh of 320 triangles whose vertices lie
// on the surface.
std::shared_ptr<const TriangleMesh> EllipsoidMesh(const Vec3& radii);

// A plane through the origin of `origin` with unit normal `normal` (in that frame) and extent size_x × size_y: a box
// of that extent, kPlaneThickness thick, whose top face is the plane. `normal` must be non-zero.
Geometry PlaneBox(const Vec3& normal, double size_x, double size_y, const Pose& origin);

}  // namespace graspsim::import
