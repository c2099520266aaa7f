// A tactile pad's sensing elements as contacts of graspsim's physics engine (physics/simulation.h): each
// element's hit (tactile/ray_caster.h) is a soft contact with the pad's foam law, told apart from the contacts of
// surface samples by its feature id, and the reaction on it is what the pad reads (SceneState::pad_forces).
#pragma once

#include <cstdint>
#include <optional>

#include "world/model.h"
#include "world/simulation_params.h"

namespace graspsim {

// The contact feature of element `element` of pad `pad`: the top bit keeps it apart from the features of
// surface samples, (geometry << 32) | sample (collision/contact_finder.h).
constexpr uint64_t PadFeature(uint32_t pad, uint32_t element) {
  return (uint64_t{1} << 63) | (uint64_t{pad} << 32) | element;
}

struct PadElementRef {
  uint32_t pad = 0;      // index into SceneModel::tactile_arrays
  uint32_t element = 0;  // index into the pad's elements (tactile/pad_elements.h)
};

// The element a contact feature names; none for a surface sample's feature.
constexpr std::optional<PadElementRef> PadElementOf(uint64_t feature) {
  if ((feature >> 63) == 0) return std::nullopt;
  return PadElementRef{static_cast<uint32_t>((feature >> 32) & 0x7fffffff), static_cast<uint32_t>(feature)};
}

// The foam's law at one sensing element. Spring, damper and bristle constants are per texel: a texel's elements
// share them out, so the pad as a whole keeps them whatever its subdivision.
inline ContactParams ElementContactParams(const TactileArraySpec& pad) {
  ContactParams law = pad.contact;
  const double share = 1.0 / pad.ElementsPerTexel();
  for (double* x :
       {&law.stiffness, &law.damping, &law.bristle_stiffness, &law.bristle_damping, &law.viscous_friction}) {
    *x *= share;
  }
  return law;
}

}  // namespace graspsim
