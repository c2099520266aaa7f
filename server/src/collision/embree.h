// The process's Embree: its one device, triangle BVHs built on it, and batches of rays cast into them. Every BVH
// of the server goes through here (collision's mesh queries, the tactile pads' segments, grasp's closing
// simulation), so the device is made once and a failure of Embree is always a graspsim::Error.
#pragma once

#include <embree3/rtcore.h>

#include <cstddef>
#include <cstdint>
#include <vector>

#include "core/math.h"
#include "core/mesh.h"

namespace graspsim::collision {

// The process's Embree device: made on first use (thread-safe), released at exit (each scene holds a reference
// to it, so none outlives it). Embree keeps an error code per thread and device, so threads sharing it do not
// read each other's errors. Throws Error(kInternal) when Embree cannot start.
RTCDevice EmbreeDevice();

// Sets *r to the ray origin + t · direction, 0 <= t <= tfar, in float as Embree casts it, with no hit yet.
inline void SetRay(RTCRayHit* r, const Vec3& origin, const Vec3& direction, float tfar, uint32_t id) {
  r->ray.org_x = static_cast<float>(origin.x());
  r->ray.org_y = static_cast<float>(origin.y());
  r->ray.org_z = static_cast<float>(origin.z());
  r->ray.dir_x = static_cast<float>(direction.x());
  r->ray.dir_y = static_cast<float>(direction.y());
  r->ray.dir_z = static_cast<float>(direction.z());
  r->ray.tnear = 0;
  r->ray.tfar = tfar;
  r->ray.time = 0;
  r->ray.mask = 0xffffffffu;
  r->ray.id = id;
  r->ray.flags = 0;
  r->hit.geomID = RTC_INVALID_GEOMETRY_ID;
  r->hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
}

// A batch of rays and their answers. Add rays (origin, unit direction, length tfar, an id of the caller's), cast
// them with EmbreeScene::Intersect; then Hit(i) tells whether ray i met a surface within [0, tfar], T(i) the
// distance to the first one and Triangle(i) its index in the mesh (both only meaningful when Hit(i)). The vector
// is reused between casts, so a warm batch allocates nothing.
struct RayBatch {
  std::vector<RTCRayHit> rays;

  void Clear() { rays.clear(); }
  void Add(const Vec3& origin, const Vec3& unit_direction, double tfar, uint32_t id) {
    SetRay(&rays.emplace_back(), origin, unit_direction, static_cast<float>(tfar), id);
  }
  size_t size() const { return rays.size(); }
  bool Hit(size_t i) const { return rays[i].hit.geomID != RTC_INVALID_GEOMETRY_ID; }
  double T(size_t i) const { return rays[i].ray.tfar; }
  uint32_t Triangle(size_t i) const { return rays[i].hit.primID; }
  uint32_t Id(size_t i) const { return rays[i].ray.id; }
  // The origin and direction as cast (rounded to float).
  Vec3 Origin(size_t i) const { return Vec3(rays[i].ray.org_x, rays[i].ray.org_y, rays[i].ray.org_z); }
  Vec3 Direction(size_t i) const { return Vec3(rays[i].ray.dir_x, rays[i].ray.dir_y, rays[i].ray.dir_z); }
};

// An Embree BVH over one triangle mesh, in the mesh's frame, on the process's device. Built robust (a ray through
// an edge two triangles share hits one of them: nothing slips through a closed surface, and crossings count
// right) at the given quality: RTC_BUILD_QUALITY_HIGH for a BVH cast against for a long time, MEDIUM (Embree's
// default) when building is the larger cost. Casting is thread-safe and allocates nothing.
class EmbreeScene {
 public:
  EmbreeScene(const TriangleMesh& mesh, RTCBuildQuality quality);
  ~EmbreeScene();
  EmbreeScene(EmbreeScene&& other) noexcept;
  EmbreeScene& operator=(EmbreeScene&& other) noexcept;
  EmbreeScene(const EmbreeScene&) = delete;
  EmbreeScene& operator=(const EmbreeScene&) = delete;

  // The first hit of every ray of the batch. The rays of a batch share a direction or sweep side by side (a pad's
  // elements, a hand link's samples), so they go as one coherent stream.
  void Intersect(RayBatch* batch) const;

  // For queries only one user makes (collision/mesh_query's parity walk and closest points).
  RTCScene handle() const { return scene_; }

 private:
  RTCScene scene_ = nullptr;
};

}  // namespace graspsim::collision
