#include "motion/sphere_kernel.h"

#include <algorithm>
#include <cmath>

#include "collision/aabb.h"
#include "core/cpu_dispatch.h"

namespace graspsim::motion::kernel {

uint32_t CollidingLanes(const Model& model, const float* q, const float* inflate, float* scratch, StopLanes stop) {
#if defined(__x86_64__)
  if (UseAvx2Kernels()) return avx2::CollidingLanes(model, q, inflate, scratch, stop);
#endif
  return generic::CollidingLanes(model, q, inflate, scratch, stop);
}

uint32_t ClearanceLanes(const Model& model, const float* q, const float* cap, float* scratch, float* clearance,
                        StopLanes stop) {
#if defined(__x86_64__)
  if (UseAvx2Kernels()) return avx2::ClearanceLanes(model, q, cap, scratch, clearance, stop);
#endif
  return generic::ClearanceLanes(model, q, cap, scratch, clearance, stop);
}

void FillObstacleBounds(const Model& model, float* out) {
  constexpr float kGrow = 1e-4f, kEmpty = 3e38f;
  const int64_t size = ObstacleBoundsSize(model);
  for (int64_t g = 0; g < size; g += 6 * kLanes) {
    for (int i = 0; i < 3 * kLanes; ++i) out[g + i] = kEmpty;
    for (int i = 3 * kLanes; i < 6 * kLanes; ++i) out[g + i] = -kEmpty;
  }
  int64_t o = 0;
  const auto put = [&](const float* centre, const double* extent) {
    float* group = out + o / kLanes * 6 * kLanes + o % kLanes;
    for (int a = 0; a < 3; ++a) {
      group[a * kLanes] = static_cast<float>(centre[a] - extent[a]) - kGrow;
      group[(3 + a) * kLanes] = static_cast<float>(centre[a] + extent[a]) + kGrow;
    }
    ++o;
  };
  for (int32_t i = 0; i < model.box_count; ++i) {
    const Box& box = model.boxes[i];
    const Vec3 half(box.half[0], box.half[1], box.half[2]);
    // rotation_t is R^T, row-major: read as column-major it is R.
    const Mat3 rotation = Eigen::Map<const Eigen::Matrix3f>(box.rotation_t).cast<double>();
    const collision::Aabb world = collision::TransformAabb({-half, half}, rotation, Vec3::Zero());
    put(box.centre, world.hi.data());  // centred on 0: its upper corner is the half-extent
  }
  for (int32_t i = 0; i < model.ball_count; ++i) {
    const double extent[3] = {model.balls[i].radius, model.balls[i].radius, model.balls[i].radius};
    put(model.balls[i].centre, extent);
  }
  for (int32_t i = 0; i < model.cylinder_count; ++i) {
    const Cylinder& cylinder = model.cylinders[i];
    double extent[3];
    for (int a = 0; a < 3; ++a) {
      const double along = cylinder.rotation_t[6 + a];  // the axis's world component a
      extent[a] = std::abs(along) * cylinder.half_length + cylinder.radius * std::sqrt(std::max(0.0, 1 - along * along));
    }
    put(cylinder.centre, extent);
  }
}

const char* KernelIsa() {
#if defined(__x86_64__)
  if (UseAvx2Kernels()) return "avx2";
  return "sse2";
#else
  return "generic";
#endif
}

}  // namespace graspsim::motion::kernel
