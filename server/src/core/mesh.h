// Triangle meshes as the engine stores them: float32 vertices (m) and uint32 index triplets, counter-clockwise
// seen from outside. float32 matches Embree's vertex buffers and the wire format.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Core>

namespace graspsim {

struct TriangleMesh {
  std::vector<Eigen::Vector3f> vertices;
  std::vector<std::array<uint32_t, 3>> triangles;

  size_t TriangleCount() const { return triangles.size(); }
};

// Checks a mesh at the boundary: at least one triangle, finite vertices, indices in range, at most
// max_triangles triangles. Throws Error naming `field` (kInvalidArgument, or kResourceExhausted for the limit).
void ValidateMesh(const TriangleMesh& mesh, const std::string& field, size_t max_triangles);

// Axis-aligned bounds of the vertices, m. The mesh must not be empty.
void MeshBounds(const TriangleMesh& mesh, Eigen::Vector3f* min, Eigen::Vector3f* max);

}  // namespace graspsim
