// Private to grasp/: an Embree BVH over one closed triangle mesh, built once (per object, per hand link) and
// queried with batches of rays for the rest of its life. Queries are thread-safe and allocate nothing.
#pragma once

#include <embree3/rtcore.h>

#include <cstdint>
#include <vector>

#include "core/math.h"
#include "core/mesh.h"

namespace graspsim::grasp {

// One Embree device for every BVH of a planner: Embree scenes must not outlive their device.
class RayDevice {
 public:
  RayDevice();
  ~RayDevice();
  RayDevice(const RayDevice&) = delete;
  RayDevice& operator=(const RayDevice&) = delete;
  RTCDevice get() const { return device_; }

 private:
  RTCDevice device_ = nullptr;
};

// A batch of rays and their answers. Add rays (origin, unit direction, length tfar), call RayScene::Intersect;
// then Hit(i) tells whether ray i met a surface within (0, tfar], T(i) the distance to the first one (only
// meaningful when Hit(i)) and Triangle(i) its index in the mesh. The vector is reused between calls, so a warm
// batch allocates nothing.
struct RayBatch {
  std::vector<RTCRayHit> rays;
  void Clear() { rays.clear(); }
  void Add(const Vec3& origin, const Vec3& unit_direction, double tfar, uint32_t id);
  size_t size() const { return rays.size(); }
  bool Hit(size_t i) const { return rays[i].hit.geomID != RTC_INVALID_GEOMETRY_ID; }
  double T(size_t i) const { return rays[i].ray.tfar; }  // the hit distance once Intersect ran
  uint32_t Triangle(size_t i) const { return rays[i].hit.primID; }
  uint32_t Id(size_t i) const { return rays[i].ray.id; }
};

class RayScene {
 public:
  RayScene(RTCDevice device, const std::vector<Vec3>& vertices, const std::vector<std::array<uint32_t, 3>>& triangles);
  RayScene(RTCDevice device, const TriangleMesh& mesh);
  ~RayScene();
  RayScene(const RayScene&) = delete;
  RayScene& operator=(const RayScene&) = delete;

  void Intersect(RayBatch* batch) const;

 private:
  void Build(RTCDevice device, const std::vector<Vec3>& vertices, const std::vector<std::array<uint32_t, 3>>& triangles);
  RTCScene scene_ = nullptr;
};

}  // namespace graspsim::grasp
