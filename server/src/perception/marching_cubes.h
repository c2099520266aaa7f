// Marching cubes (Lorensen & Cline 1987) on a regular grid of samples: the iso-surface value = iso as triangles.
//
// The case table (256 corner sign patterns → triangles over the cube's 12 edges) is derived once, at first use,
// from the face rule rather than typed in: on each cube face the contour joins the edge crossings so that inside
// corners are kept apart ("separate the inside", the same choice for every ambiguous face), and the face
// contours chain into closed loops that are fanned into triangles. Both cells that share a face make the same
// choice on it, so the surface has no cracks: where the inside region stays off the grid's border the mesh is
// closed, and vertices on shared edges are shared. Triangles are counter-clockwise seen from the outside, the side
// with values ≥ iso.
#pragma once

#include "core/math.h"
#include "core/mesh.h"

namespace graspsim {

// A read-only view of nodes[0] × nodes[1] × nodes[2] samples, x fastest; node (i, j, k) sits at
// origin + spacing · (i, j, k) (m).
struct GridSamples {
  Eigen::Vector3i nodes;
  Vec3 origin = Vec3::Zero();
  double spacing = 1;
  const float* values = nullptr;
};

// "Inside" is value < iso. Vertices on edges by linear interpolation.
TriangleMesh ExtractIsoSurface(const GridSamples& grid, float iso);

}  // namespace graspsim
