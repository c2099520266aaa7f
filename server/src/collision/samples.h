// Private to collision/: surface samples of collision geometries, grouped into small spatially coherent blocks so
// that a pair test can skip most of a large body (a table) with one box test per block.
#pragma once

#include <cstdint>
#include <limits>
#include <vector>

#include "core/math.h"
#include "world/model.h"

namespace graspsim::collision {

// An axis-aligned box, m. Empty when lo > hi on any axis.
struct Aabb {
  Vec3 lo = Vec3::Constant(std::numeric_limits<double>::infinity());
  Vec3 hi = Vec3::Constant(-std::numeric_limits<double>::infinity());

  bool Empty() const { return (lo.array() > hi.array()).any(); }
  void Add(const Vec3& p) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  void Add(const Aabb& b) {
    lo = lo.cwiseMin(b.lo);
    hi = hi.cwiseMax(b.hi);
  }
  bool Overlaps(const Aabb& b) const {
    return (lo.array() <= b.hi.array()).all() && (b.lo.array() <= hi.array()).all();
  }
};

// The box that holds `box` after the rigid map x -> rotation * x + translation.
inline Aabb TransformAabb(const Aabb& box, const Mat3& rotation, const Vec3& translation) {
  if (box.Empty()) return box;
  const Vec3 centre = rotation * (0.5 * (box.lo + box.hi)) + translation;
  const Vec3 extent = rotation.cwiseAbs() * (0.5 * (box.hi - box.lo));
  return {centre - extent, centre + extent};
}

// A run of consecutive samples [begin, end) of one geometry and their bounds in the body frame.
struct SampleBlock {
  Aabb bounds;
  uint32_t begin = 0, end = 0;
};

struct BodySamples {
  std::vector<Vec3> points;         // body frame, m
  std::vector<uint64_t> features;   // (geometry index << 32) | sample index, ascending
  std::vector<SampleBlock> blocks;  // cover `points` in order
};

// At most this many samples per primitive: a 10 m floor at 5 mm spacing would need 8 million. Beyond it the
// spacing of that one geometry is doubled until it fits (deterministically), which only coarsens where the
// floor's own samples dig into others; other bodies' samples into the floor stay as dense as asked.
inline constexpr size_t kMaxSamplesPerPrimitive = size_t{1} << 18;
inline constexpr uint32_t kBlockSize = 32;

// Surface samples of one geometry in its own frame (origin not applied), in a deterministic order.
// Box: every point of a regular lattice on its surface (corners and edges included, no duplicates).
// Sphere: a Fibonacci set plus both poles. Cylinder: rings on both caps (centre included) and on the side.
// Mesh: its referenced vertices, each once.
std::vector<Vec3> SampleGeometry(const Geometry& geometry, double spacing);

// Bounds of a geometry in its own frame, m.
Aabb GeometryBounds(const Geometry& geometry);

// Every collision geometry of `body`, sampled and placed in the body frame, sorted along a Morton curve within
// each geometry (feature ids number the sorted samples) and cut into blocks of kBlockSize.
BodySamples SampleBody(const BodySpec& body, double spacing);

}  // namespace graspsim::collision
