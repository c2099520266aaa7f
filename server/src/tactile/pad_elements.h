// A tactile pad's sensing elements (PAPERS.md part B, "Sensor construction").
//
// A pad (TactileArraySpec) is a triangle-mesh grid over (rows · s) × (cols · s) equal cells (s = subdivision) of
// the surface the foam is mounted on, flat at z = 0 or wrapped into a curved fingertip (PadSurfacePoint). Its
// sensing elements are either the mesh's vertices at the cell centres, each with the normalised sum of its
// adjacent faces' normals, or the centroids of the triangles of a mesh whose vertices are the cell corners, each
// with its face's normal (TactileArraySpec::placement). Each element casts a segment of length `thickness` from
// its base point along its normal, into the foam (tactile/ray_caster.h).
#pragma once

#include <cstdint>
#include <utility>
#include <vector>

#include "core/math.h"
#include "world/model.h"

namespace graspsim {

struct PadElement {
  Vec3 position = Vec3::Zero();  // pad frame, m (z = 0)
  Vec3 normal = Vec3::UnitZ();   // pad frame, unit
  uint32_t row = 0, col = 0;     // the texel the element belongs to (row along pad y, col along pad x)
};

// The elements of one pad, row-major over the cell grid (r along pad y from −rows·pitch/2, c along pad x from
// −cols·pitch/2, s = subdivision): at vertices, element r · (cols · s) + c is cell (r, c)'s centre; at face
// centres, elements 2 (r · cols · s + c) and that + 1 are the centroids of cell (r, c)'s two triangles.
std::vector<PadElement> MakePadElements(const TactileArraySpec& pad);

// The texel (row, col) of element `element` of `pad`, as MakePadElements assigns it, without building the grid.
inline std::pair<uint32_t, uint32_t> ElementTexel(const TactileArraySpec& pad, uint32_t element) {
  const uint32_t s = pad.subdivision > 0 ? pad.subdivision : 1;
  const uint32_t per_row = pad.cols * s;
  const uint32_t cell = pad.placement == PadElementPlacement::kFaceCentres ? element / 2 : element;
  return {cell / per_row / s, cell % per_row / s};
}

// The point of the pad's mounting surface over grid position (x, y) of the flat sensing area (pad frame): the
// identity for a flat pad, the wrapped point for a curved fingertip (TactileArraySpec::bend_radius_x/_y).
Vec3 PadSurfacePoint(const TactileArraySpec& pad, double x, double y);

}  // namespace graspsim
