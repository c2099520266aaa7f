// Closed triangle meshes of the collision primitives, for ray casting against them (tactile/ray_caster):
// boxes exactly, spheres and cylinders inscribed within a chord error of 0.1 mm, counter-clockwise from outside.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "core/math.h"

namespace graspsim::collision {

// A triangle soup in double, one geometry in its own frame before placement.
struct LocalMesh {
  std::vector<Vec3> vertices;
  std::vector<std::array<uint32_t, 3>> triangles;
};

LocalMesh BoxMesh(const Vec3& half);
LocalMesh SphereMesh(double radius);
LocalMesh CylinderMesh(double radius, double half_length);  // along z

}  // namespace graspsim::collision
