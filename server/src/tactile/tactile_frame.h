// A tactile pad's reading as the real device delivers it (PAPERS.md part B): a frame in the structure of the
// Weiss DSACON32 controller, 12-bit intensities per texel. Computed from a scene's model and state after a
// simulation step; the physics fills SceneState::pad_forces (per sensing element, world frame).
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "core/math.h"
#include "world/model.h"
#include "world/state.h"

namespace graspsim {

// One DSACON32-style frame: rows × cols texels, row-major (row along pad y, col along pad x).
struct TactileFrame {
  unsigned rows = 0, cols = 0;
  std::vector<uint16_t> intensities;  // 0..max_intensity: round(intensity_per_newton · texel normal force), saturated
  std::vector<Vec3> forces;           // per texel: the force the object exerts on the pad, pad frame, N
  uint64_t intensity_sum = 0;
  Vec3 force_sum = Vec3::Zero();      // pad frame, N
};

// The frame of tactile array `pad` (index into model.tactile_arrays) in `state`. The pad's +z points out of the
// foam toward what it touches, so an object pressing on the pad pushes it along −z: the texel's normal force is
// max(0, −z) of its force (a force along +z would pull the foam off and reads 0).
TactileFrame ReadTactileArray(const SceneModel& model, const SceneState& state, size_t pad);
// The same into *frame, reusing its buffers (a controller reading the pads every few steps).
void ReadTactileArray(const SceneModel& model, const SceneState& state, size_t pad, TactileFrame* frame);

}  // namespace graspsim
