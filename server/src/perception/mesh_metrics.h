// Evaluation metrics of a reconstructed mesh (issue 5, "Metrics"): closedness, enclosed volume, uniform surface
// samples, and the distance from points to a mesh, for the mesh deviation of Bohg et al. (PAPERS.md part C: sample
// one surface uniformly, mean distance of the samples to the other).
#pragma once

#include <cstdint>
#include <vector>

#include "core/math.h"
#include "core/mesh.h"

namespace graspsim {

// Undirected edges by how many triangles use them: a closed, consistently oriented mesh has every edge in exactly
// two triangles that traverse it in opposite directions.
struct EdgeCounts {
  size_t edges = 0;
  size_t boundary = 0;      // in one triangle
  size_t non_manifold = 0;  // in three or more
  size_t misoriented = 0;   // in two triangles that run it the same way
  bool Closed() const { return edges > 0 && boundary == 0 && non_manifold == 0 && misoriented == 0; }
};
EdgeCounts CountEdges(const TriangleMesh& mesh);

// Signed volume by the divergence theorem, m³: positive for a closed mesh whose triangles are counter-clockwise
// seen from outside.
double EnclosedVolume(const TriangleMesh& mesh);

// `count` points uniform over the surface (triangles chosen by area), reproducible for a seed.
std::vector<Vec3> SampleSurface(const TriangleMesh& mesh, size_t count, uint64_t seed);

// Distances from points to the nearest point of a mesh's triangles, through a uniform grid of triangle buckets.
class MeshDistance {
 public:
  explicit MeshDistance(const TriangleMesh& mesh);  // a non-empty mesh; it must outlive this object
  double Distance(const Vec3& point) const;

 private:
  int64_t CellIndex(int x, int y, int z) const { return (int64_t(z) * dims_[1] + y) * dims_[0] + x; }
  Eigen::Vector3i CellOf(const Vec3& p) const;

  const TriangleMesh& mesh_;
  Vec3 origin_;
  double cell_size_ = 0;
  Eigen::Vector3i dims_;
  std::vector<uint32_t> cell_start_, triangles_;  // CSR buckets
};

}  // namespace graspsim
