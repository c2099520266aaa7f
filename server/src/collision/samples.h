// Private to collision/: surface samples of collision geometries, grouped into small spatially coherent blocks so
// that a pair test can skip most of a large body (a table) with one box test per block.
#pragma once

#include <cstdint>
#include <vector>

#include "collision/aabb.h"
#include "core/math.h"
#include "world/model.h"

namespace graspsim::collision {

// A run of consecutive samples [begin, end) of one geometry and their bounds in the body frame.
struct SampleBlock {
  Aabb bounds;
  uint32_t begin = 0, end = 0;
};

struct BodySamples {
  std::vector<Vec3> points;         // body frame, m
  std::vector<uint64_t> features;   // (geometry index << 32) | sample index, ascending
  std::vector<SampleBlock> blocks;  // cover `points` in order
  // Runs of kBlocksPerGroup consecutive blocks, [begin, end) into `blocks`, and their bounds: a table has
  // thousands of blocks, of which a pair test meets a handful.
  std::vector<SampleBlock> groups;
};

// At most this many samples per primitive: a 10 m floor at 5 mm spacing would need 8 million. Beyond it the
// spacing of that one geometry is doubled until it fits (deterministically), which only coarsens where the
// floor's own samples dig into others; other bodies' samples into the floor stay as dense as asked.
inline constexpr size_t kMaxSamplesPerPrimitive = size_t{1} << 18;
inline constexpr uint32_t kBlockSize = 32;
inline constexpr uint32_t kBlocksPerGroup = 32;

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
