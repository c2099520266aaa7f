// Private to collision/: point queries against a closed triangle mesh on an Embree BVH built once and reused
// for every pose (queries come in the mesh's own frame).
#pragma once

#include <embree3/rtcore.h>

#include <memory>
#include <vector>

#include "core/math.h"
#include "core/mesh.h"

namespace graspsim::collision {

// The point of triangle (a, b, c) closest to p (Ericson, Real-Time Collision Detection, §5.1.5): Voronoi
// regions of the vertices, then of the edges, else the face. Degenerate triangles fall into a vertex or edge.
Vec3 ClosestPointOnTriangle(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c);

// One Embree device; owned by a ContactFinder so its scenes die with it.
class EmbreeDevice {
 public:
  EmbreeDevice();
  ~EmbreeDevice();
  EmbreeDevice(const EmbreeDevice&) = delete;
  EmbreeDevice& operator=(const EmbreeDevice&) = delete;
  RTCDevice get() const { return device_; }

 private:
  RTCDevice device_ = nullptr;
};

class MeshBvh {
 public:
  // Copies the mesh into Embree buffers (Embree pads them for its vector loads) and builds the BVH; keeps a
  // reference to the mesh for the exact closest-point arithmetic.
  MeshBvh(RTCDevice device, std::shared_ptr<const TriangleMesh> mesh);
  ~MeshBvh();
  MeshBvh(const MeshBvh&) = delete;
  MeshBvh& operator=(const MeshBvh&) = delete;

  // Penetration of p (mesh frame, m) into the closed mesh: *depth > 0 inside (distance to the surface), < 0
  // outside. Returns false, leaving the outputs alone, when p is outside and not closer than `margin` (or
  // `margin` is 0). *normal: the outward unit normal of the triangle holding the closest surface point.
  // Thread-safe; allocates nothing.
  bool Depth(const Vec3& p, double margin, double* depth, Vec3* normal) const;

 private:
  RTCScene scene_ = nullptr;
  std::shared_ptr<const TriangleMesh> mesh_;
  std::vector<Vec3> normals_;                // unit face normals; zero for degenerate triangles
  Vec3 centre_ = Vec3::Zero();               // of the bounding box: parity rays point away from it
  double near_surface_ = 0;                  // m: below this, float rounding can flip a ray's parity
};

}  // namespace graspsim::collision
