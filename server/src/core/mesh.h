// Triangle meshes as the engine stores them: float32 vertices (m) and uint32 index triplets, counter-clockwise
// seen from outside. float32 matches Embree's vertex buffers and the wire format.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "core/math.h"

namespace graspsim {

struct TriangleMesh {
  std::vector<Eigen::Vector3f> vertices;
  std::vector<std::array<uint32_t, 3>> triangles;

  size_t TriangleCount() const { return triangles.size(); }
};

// Checks a mesh at the boundary: at least one triangle, finite vertices, indices in range, at most
// max_triangles triangles. Throws Error naming `field` (kInvalidArgument, or kResourceExhausted for the limit).
void ValidateMesh(const TriangleMesh& mesh, const std::string& field, size_t max_triangles);

// The solid a closed mesh bounds (counter-clockwise from outside): volume (m³), centroid (m) and the second
// moment ∫ (x − c)(x − c)ᵀ dV (m⁵), by the signed tetrahedra (origin, a, b, c) of the divergence theorem (Tonon 2004). A mesh wound inside out
// gives a negative volume and second moment. A body of
// uniform density ρ has the inertia ρ (trace(C) I − C) about its centroid.
struct SolidProperties {
  double volume = 0;
  Vec3 centroid = Vec3::Zero();
  Mat3 second_moment = Mat3::Zero();
};
SolidProperties ComputeSolidProperties(const TriangleMesh& mesh);

// Axis-aligned bounds of the vertices, m. The mesh must not be empty.
void MeshBounds(const TriangleMesh& mesh, Eigen::Vector3f* min, Eigen::Vector3f* max);

}  // namespace graspsim
