// The segments a tactile pad's sensing elements (tactile/pad_elements.h) cast into the foam, every physics step.
//
// The first surface of another body a segment enters, at distance t, is a contact with penetration
// d = thickness − t (the object has compressed the foam that far). A segment that starts inside a body (first
// surface hit from inside) reports d = thickness at the base point: fully compressed.
//
// Targets are every body's collision geometry: a body that is one box is met analytically (slab test, double
// precision); any other is triangulated once per model (boxes exactly, spheres and cylinders tessellated to a
// chord error of 0.1 mm, meshes as given), and each segment is tested in double precision against the triangles
// near it, gathered while the pad moves little relative to the body (tactile/near_triangles.h), with Embree's
// BVH (collision/embree.h) for what those cannot answer. A pad only casts against bodies whose world bounding box overlaps
// its foam's world bounding box (nothing near: no rays at all), never against links of its own robot.
#pragma once

#include <cstdint>
#include <memory>
#include <vector>

#include "core/math.h"
#include "tactile/pad_elements.h"
#include "world/model.h"

namespace graspsim {

struct PadHit {
  uint32_t pad = 0;       // index into SceneModel::tactile_arrays
  uint32_t element = 0;   // index into Elements(pad)
  uint32_t body = 0;      // the touched body (index into SceneModel::bodies)
  double depth = 0;       // m, in (0, thickness]
  Vec3 point = Vec3::Zero();   // world, where the segment enters the body (the base point when fully compressed)
  Vec3 normal = Vec3::UnitZ(); // world, the element's normal (out of the pad, toward the object)
};

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

  // How often the mesh path gathered candidate triangles so far, over all pads and bodies (for tests: the
  // candidates are kept while a pad moves little relative to the mesh).
  uint64_t candidate_gathers() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace graspsim
