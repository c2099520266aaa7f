// Contact generation for soft (penalty) contacts: which surface samples of one body lie inside another, how
// deep, and along which normal. Every body's collision geometry is covered by surface samples (box corners and
// face grids, sphere and cylinder point sets, mesh vertices) made once per model; a sample inside another body is
// one contact point. Primitives are tested with their exact signed distance; meshes with Embree (rtcPointQuery
// for the closest point, a ray for inside/outside), on a BVH built once per mesh and reused for every pose.
// Pairs are culled by world bounding boxes first; static–static pairs and links of the same robot are skipped.
// Curved surfaces against primitives are the exception, so that they roll as they should: a sphere against a
// primitive (box, sphere, cylinder) gets one exact contact at its deepest point (feature (geometry << 32) |
// 0xffff0000 | target geometry) instead of the samples of either side; a cylinder against a box gets the deepest
// point of each cap's rim (0xffff0000 | target geometry << 1 | cap) instead of its side and rim samples.
#pragma once

#include <cstdint>
#include <memory>
#include <vector>

#include "core/math.h"
#include "world/model.h"

namespace graspsim {

struct ContactPoint {
  uint32_t body_a = 0, body_b = 0;  // the sample belongs to body_a and lies inside body_b
  uint64_t feature = 0;             // stable id of the sample on body_a: (geometry index << 32) | sample index
  Vec3 point = Vec3::Zero();        // world position of the sample, m
  Vec3 normal = Vec3::UnitZ();      // world unit normal of body_b's surface nearest the sample, out of body_b
  double depth = 0;                 // penetration along the normal, m, > 0
};

struct ContactFinderOptions {
  double sample_spacing = 0.005;  // m, largest distance between neighbouring samples on a primitive's surface
  double margin = 0;              // m: samples up to this far outside are reported too (depth <= 0), for sensors
};

class ContactFinder {
 public:
  // Samples every collision geometry of `model` and builds the mesh BVHs. `model` must outlive the finder.
  ContactFinder(const SceneModel& model, const ContactFinderOptions& options = {});
  ~ContactFinder();
  ContactFinder(const ContactFinder&) = delete;
  ContactFinder& operator=(const ContactFinder&) = delete;
  ContactFinder(ContactFinder&&) noexcept;
  ContactFinder& operator=(ContactFinder&&) noexcept;

  // All contact points for the given world body poses (indexed like model.bodies), appended to *contacts in a
  // deterministic order (by body_a, body_b, feature).
  void Find(const std::vector<Pose>& body_poses, std::vector<ContactPoint>* contacts) const;

  // Surface samples of one body in its own frame (for tests and viewers).
  const std::vector<Vec3>& Samples(uint32_t body) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace graspsim
