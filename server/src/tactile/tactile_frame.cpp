// A tactile pad's frame from the physics' element forces (see tactile_frame.h).
#include "tactile/tactile_frame.h"

#include <algorithm>
#include <cmath>

#include "tactile/pad_elements.h"

namespace graspsim {

TactileFrame ReadTactileArray(const SceneModel& model, const SceneState& state, size_t pad) {
  TactileFrame frame;
  ReadTactileArray(model, state, pad, &frame);
  return frame;
}

void ReadTactileArray(const SceneModel& model, const SceneState& state, size_t pad, TactileFrame* out) {
  const TactileArraySpec& spec = model.tactile_arrays.at(pad);
  TactileFrame& frame = *out;
  frame.intensity_sum = 0;
  frame.force_sum = Vec3::Zero();
  frame.rows = spec.rows;
  frame.cols = spec.cols;
  const size_t texels = size_t{spec.rows} * spec.cols;
  frame.forces.assign(texels, Vec3::Zero());
  frame.intensities.assign(texels, 0);

  // The simulation sizes pad_forces only once it has stepped: a scene that never ran reads as untouched.
  if (pad < state.pad_forces.size() && !state.pad_forces[pad].empty()) {
    const std::vector<Vec3>& element_forces = state.pad_forces[pad];
    const size_t n = std::min(spec.ElementCount(), element_forces.size());
    for (size_t i = 0; i < n; ++i) {
      const auto [row, col] = ElementTexel(spec, static_cast<uint32_t>(i));
      frame.forces[size_t{row} * spec.cols + col] += element_forces[i];
    }
  }

  // World → pad frame: only the rotation matters for forces.
  const Pose& link = state.body_poses.at(model.body_index.at(spec.body_id));
  // As a matrix: one conversion per frame rather than a quaternion product per texel.
  const Mat3 world_to_pad = (link * spec.origin).orientation.conjugate().toRotationMatrix();
  const double max_intensity = spec.max_intensity;
  for (size_t t = 0; t < texels; ++t) {
    Vec3& force = frame.forces[t];
    force = world_to_pad * force;
    // Pressing pushes the pad along its −z (into the foam); +z would be the object pulling, which a foam sensor
    // cannot feel (the contact law never pulls; this is a guard, not a case).
    const double scaled = spec.intensity_per_newton * std::max(0.0, -force.z());
    // Saturate before rounding so that huge (or infinite) forces cannot overflow the integer conversion.
    const uint16_t intensity = !(scaled < max_intensity)
                                   ? static_cast<uint16_t>(spec.max_intensity)
                                   : static_cast<uint16_t>(std::lround(scaled));
    frame.intensities[t] = intensity;
    frame.intensity_sum += intensity;
    frame.force_sum += force;
  }
}

}  // namespace graspsim
