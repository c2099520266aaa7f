#include "grasp/ray_scene.h"

#include <limits>
#include <string>

#include "core/error.h"

namespace graspsim::grasp {
namespace {

[[noreturn]] void ThrowEmbree(RTCDevice device, const char* what) {
  throw Error(ErrorCode::kInternal, std::string("embree: ") + what + " failed (error " +
                                        std::to_string(device ? rtcGetDeviceError(device) : -1) + ")");
}

}  // namespace

RayDevice::RayDevice() {
  device_ = rtcNewDevice(nullptr);
  if (device_ == nullptr) ThrowEmbree(nullptr, "rtcNewDevice");
}

RayDevice::~RayDevice() { rtcReleaseDevice(device_); }

void RayBatch::Add(const Vec3& origin, const Vec3& unit_direction, double tfar, uint32_t id) {
  RTCRayHit& r = rays.emplace_back();
  r.ray.org_x = static_cast<float>(origin.x());
  r.ray.org_y = static_cast<float>(origin.y());
  r.ray.org_z = static_cast<float>(origin.z());
  r.ray.dir_x = static_cast<float>(unit_direction.x());
  r.ray.dir_y = static_cast<float>(unit_direction.y());
  r.ray.dir_z = static_cast<float>(unit_direction.z());
  r.ray.tnear = 0;
  r.ray.tfar = static_cast<float>(tfar);
  r.ray.time = 0;
  r.ray.mask = 0xffffffffu;
  r.ray.id = id;
  r.ray.flags = 0;
  r.hit.geomID = RTC_INVALID_GEOMETRY_ID;
  r.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
}

RayScene::RayScene(RTCDevice device, const std::vector<Vec3>& vertices,
                   const std::vector<std::array<uint32_t, 3>>& triangles) {
  Build(device, vertices, triangles);
}

RayScene::RayScene(RTCDevice device, const TriangleMesh& mesh) {
  std::vector<Vec3> vertices;
  vertices.reserve(mesh.vertices.size());
  for (const auto& v : mesh.vertices) vertices.push_back(v.cast<double>());
  Build(device, vertices, mesh.triangles);
}

void RayScene::Build(RTCDevice device, const std::vector<Vec3>& vertices,
                     const std::vector<std::array<uint32_t, 3>>& triangles) {
  RTCGeometry geometry = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_TRIANGLE);
  if (geometry == nullptr) ThrowEmbree(device, "rtcNewGeometry");
  auto* vertex_buffer = static_cast<float*>(rtcSetNewGeometryBuffer(
      geometry, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 3 * sizeof(float), vertices.size()));
  auto* index_buffer = static_cast<uint32_t*>(rtcSetNewGeometryBuffer(
      geometry, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 3 * sizeof(uint32_t), triangles.size()));
  if (vertex_buffer == nullptr || index_buffer == nullptr) {
    rtcReleaseGeometry(geometry);
    ThrowEmbree(device, "rtcSetNewGeometryBuffer");
  }
  for (size_t i = 0; i < vertices.size(); ++i) {
    for (int k = 0; k < 3; ++k) vertex_buffer[3 * i + k] = static_cast<float>(vertices[i][k]);
  }
  for (size_t i = 0; i < triangles.size(); ++i) {
    for (int k = 0; k < 3; ++k) index_buffer[3 * i + k] = triangles[i][k];
  }
  rtcCommitGeometry(geometry);
  scene_ = rtcNewScene(device);
  // Robust traversal: a ray through a shared edge must not slip between two triangles, or a finger would pass
  // through the object there.
  rtcSetSceneFlags(scene_, RTC_SCENE_FLAG_ROBUST);
  rtcSetSceneBuildQuality(scene_, RTC_BUILD_QUALITY_HIGH);  // built once, queried millions of times
  rtcAttachGeometry(scene_, geometry);
  rtcReleaseGeometry(geometry);
  rtcCommitScene(scene_);
  if (rtcGetDeviceError(device) != RTC_ERROR_NONE) {
    rtcReleaseScene(scene_);
    scene_ = nullptr;
    ThrowEmbree(device, "building a BVH");
  }
}

RayScene::~RayScene() {
  if (scene_) rtcReleaseScene(scene_);
}

void RayScene::Intersect(RayBatch* batch) const {
  if (batch->rays.empty()) return;
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  // The rays of a batch share a direction (an approach) or sweep one link: coherent streams are faster.
  context.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
  rtcIntersect1M(scene_, &context, batch->rays.data(), static_cast<unsigned>(batch->rays.size()), sizeof(RTCRayHit));
}

}  // namespace graspsim::grasp
