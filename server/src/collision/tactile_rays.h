// Tactile pad sensing elements and the segments they cast (PAPERS.md part B, "Sensor construction").
//
// A pad (TactileArraySpec) is a triangle-mesh grid over (rows · s) × (cols · s) equal cells (s = subdivision) of
// the surface the foam is mounted on, flat at z = 0 or wrapped into a curved fingertip (PadSurfacePoint). Its
// sensing elements are either the mesh's vertices at the cell centres, each with the normalised sum of its
// adjacent faces' normals, or the centroids of the triangles of a mesh whose vertices are the cell corners, each
// with its face's normal (TactileArraySpec::placement). Each element casts a segment of length `thickness` from its base point along its normal,
// into the foam. The first surface of another body it enters, at distance t, is a contact with penetration
// d = thickness − t (the object has compressed the foam that far). A segment that starts inside a body
// (first surface hit from inside) reports d = thickness at the base point: fully compressed.
//
// Targets are every body's collision geometry: a body that is one box is met analytically (slab test, double
// precision); any other is triangulated once per model (boxes exactly, spheres and cylinders
// tessellated to a chord error of 0.1 mm, meshes as given) in Embree BVHs in body frames; rays are transformed into
// each candidate body's frame. A pad only casts against bodies whose world bounding box overlaps its foam's world
// bounding box (nothing near: no rays at all), never against links of its own robot.
#pragma once

#include <cstdint>
#include <memory>
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

struct PadHit {
  uint32_t pad = 0;       // index into SceneModel::tactile_arrays
  uint32_t element = 0;   // index into Elements(pad)
  uint32_t body = 0;      // the touched body (index into SceneModel::bodies)
  double depth = 0;       // m, in (0, thickness]
  Vec3 point = Vec3::Zero();   // world, where the segment enters the body (the base point when fully compressed)
  Vec3 normal = Vec3::UnitZ(); // world, the element's normal (out of the pad, toward the object)
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

class TactileRayCaster {
 public:
  // Builds the elements of every pad and the BVHs of every body. `model` must outlive the caster.
  explicit TactileRayCaster(const SceneModel& model);
  ~TactileRayCaster();
  TactileRayCaster(TactileRayCaster&&) noexcept;
  TactileRayCaster& operator=(TactileRayCaster&&) noexcept;

  // MakePadElements of pad `pad`, built once.
  const std::vector<PadElement>& Elements(uint32_t pad) const;

  // One hit at most per element (the nearest entry over all bodies), appended to *hits ordered by (pad, element).
  // Pad poses come from the body poses (the pad's link) and the pad origins.
  void Cast(const std::vector<Pose>& body_poses, std::vector<PadHit>* hits) const;

  // Segments cast by the last Cast (for benchmarks: rays per second).
  uint64_t last_ray_count() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace graspsim
