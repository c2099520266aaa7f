// Private to collision/: point queries against a closed triangle mesh on an Embree BVH built once and reused
// for every pose (queries come in the mesh's own frame).
#pragma once

#include <atomic>
#include <cstdint>
#include <limits>
#include <memory>
#include <vector>

#include "collision/embree.h"
#include "core/math.h"
#include "core/mesh.h"

namespace graspsim::collision {

// The point of triangle (a, b, c) closest to p (Ericson, Real-Time Collision Detection, §5.1.5): Voronoi
// regions of the vertices, then of the edges, else the face. Degenerate triangles fall into a vertex or edge.
Vec3 ClosestPointOnTriangle(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c);

// Search state of one closest-point query, passed to Embree's callback through userPtr.
struct ClosestSearch {
  const TriangleMesh* mesh;
  const std::vector<Vec3>* normals;
  Vec3 p;
  double best_d2;  // starts at the query radius squared: nothing farther counts
  uint32_t best_triangle = std::numeric_limits<uint32_t>::max();
  Vec3 best_point = Vec3::Zero();
};

class MeshBvh {
 public:
  // Builds the BVH; keeps a reference to the mesh for the exact closest-point arithmetic.
  explicit MeshBvh(std::shared_ptr<const TriangleMesh> mesh);

  // Penetration of p (mesh frame, m) into the closed mesh: *depth > 0 inside (distance to the surface), < 0
  // outside. Returns false, leaving the outputs alone, when p is outside and not closer than `margin` (or
  // `margin` is 0). *normal: the outward unit normal of the triangle holding the closest surface point.
  // Thread-safe; allocates nothing.
  bool Depth(const Vec3& p, double margin, double* depth, Vec3* normal) const;

 private:
  int Crossings(const Vec3& p, float* first_hit) const;
  ClosestSearch Closest(const Vec3& p, float radius) const;
  // A lower bound on p's distance outside the surface from p's cell of a grid over the bounding box (0: none).
  double Clearance(const Vec3& p) const;

  std::shared_ptr<const TriangleMesh> mesh_;
  EmbreeScene scene_;                        // declared after mesh_: built from it
  std::vector<Vec3> normals_;                // unit face normals; zero for degenerate triangles
  Vec3 centre_ = Vec3::Zero();               // of the bounding box: parity rays point away from it
  double near_surface_ = 0;                  // m: below this, float rounding can flip a ray's parity
  Vec3 grid_origin_ = Vec3::Zero();          // the clearance grid: its corner, cell edge (m) and cells per axis
  double cell_size_ = 1;
  Eigen::Vector3i grid_cells_ = Eigen::Vector3i::Ones();
  std::unique_ptr<std::atomic<float>[]> clearance_;  // per cell, filled on first use (Clearance)
};

}  // namespace graspsim::collision
