// The process's Embree device and its triangle BVHs (see embree.h).
#include "collision/embree.h"

#include <cstring>
#include <string>
#include <utility>

#include "core/error.h"

namespace graspsim::collision {
namespace {

[[noreturn]] void ThrowEmbree(RTCDevice device, const std::string& what) {
  throw Error(ErrorCode::kInternal,
              "embree: " + what + " failed (error " + std::to_string(rtcGetDeviceError(device)) + ")");
}

// Owns the device; a function-local static of this type makes it once, whichever thread asks first. When making
// it throws, the next call tries again.
struct Device {
  RTCDevice handle = rtcNewDevice(nullptr);
  Device() {
    if (handle == nullptr) ThrowEmbree(nullptr, "rtcNewDevice");  // a null device reads the creation's error
  }
  ~Device() { rtcReleaseDevice(handle); }
  Device(const Device&) = delete;
  Device& operator=(const Device&) = delete;
};

}  // namespace

RTCDevice EmbreeDevice() {
  static const Device device;
  return device.handle;
}

EmbreeScene::EmbreeScene(const TriangleMesh& mesh, RTCBuildQuality quality) {
  static_assert(sizeof(mesh.vertices[0]) == 3 * sizeof(float) && sizeof(mesh.triangles[0]) == 3 * sizeof(uint32_t),
                "TriangleMesh's vertices and triangles are packed as Embree's FLOAT3 and UINT3 buffers");
  RTCDevice device = EmbreeDevice();
  // Embree keeps a thread's first error until it is read: clear one nobody read, so it is not taken for ours.
  rtcGetDeviceError(device);
  RTCGeometry geometry = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_TRIANGLE);
  if (geometry == nullptr) ThrowEmbree(device, "rtcNewGeometry");
  // Embree's own buffers: it pads them for its vector loads.
  void* vertices = rtcSetNewGeometryBuffer(geometry, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3,
                                           3 * sizeof(float), mesh.vertices.size());
  void* indices = rtcSetNewGeometryBuffer(geometry, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
                                          3 * sizeof(uint32_t), mesh.triangles.size());
  if (vertices == nullptr || indices == nullptr) {
    rtcReleaseGeometry(geometry);
    ThrowEmbree(device, "rtcSetNewGeometryBuffer");
  }
  if (!mesh.vertices.empty()) std::memcpy(vertices, mesh.vertices.data(), mesh.vertices.size() * 3 * sizeof(float));
  if (!mesh.triangles.empty()) {
    std::memcpy(indices, mesh.triangles.data(), mesh.triangles.size() * 3 * sizeof(uint32_t));
  }
  rtcCommitGeometry(geometry);
  scene_ = rtcNewScene(device);
  if (scene_ == nullptr) {
    rtcReleaseGeometry(geometry);
    ThrowEmbree(device, "rtcNewScene");
  }
  rtcSetSceneFlags(scene_, RTC_SCENE_FLAG_ROBUST);
  rtcSetSceneBuildQuality(scene_, quality);
  rtcAttachGeometry(scene_, geometry);
  rtcReleaseGeometry(geometry);
  rtcCommitScene(scene_);
  if (rtcGetDeviceError(device) != RTC_ERROR_NONE) {
    rtcReleaseScene(scene_);
    scene_ = nullptr;
    ThrowEmbree(device, "building the BVH of " + std::to_string(mesh.triangles.size()) + " triangles");
  }
}

EmbreeScene::~EmbreeScene() {
  if (scene_ != nullptr) rtcReleaseScene(scene_);
}

EmbreeScene::EmbreeScene(EmbreeScene&& other) noexcept : scene_(std::exchange(other.scene_, nullptr)) {}

EmbreeScene& EmbreeScene::operator=(EmbreeScene&& other) noexcept {
  if (this != &other) {
    if (scene_ != nullptr) rtcReleaseScene(scene_);
    scene_ = std::exchange(other.scene_, nullptr);
  }
  return *this;
}

void EmbreeScene::Intersect(RayBatch* batch) const {
  if (batch->rays.empty()) return;
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  context.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
  rtcIntersect1M(scene_, &context, batch->rays.data(), static_cast<unsigned>(batch->rays.size()), sizeof(RTCRayHit));
}

}  // namespace graspsim::collision
