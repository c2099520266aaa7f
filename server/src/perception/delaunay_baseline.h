// The paper's baseline (PAPERS.md part C, "Baseline"): a mesh of what was seen, without completion. 500 points
// drawn uniformly (seeded) from the partial cloud, projected onto the camera's image plane and Delaunay
// triangulated there (OpenCV's Subdiv2D); triangles with an edge longer than max_edge_factor × the median edge (in
// 3D) are dropped — they bridge gaps and silhouettes. The sheet is closed into a watertight mesh by its own
// reversed copy (a shell of zero thickness: every edge in one front and one back triangle), because the baseline
// claims nothing about the unseen side.
#pragma once

#include <cstdint>
#include <vector>

#include "core/math.h"
#include "core/mesh.h"

namespace graspsim {

struct DelaunayParams {
  int samples = 500;             // points drawn from the cloud, 3..100000 (all when the cloud has fewer)
  uint64_t seed = 1;
  double max_edge_factor = 3;    // > 1
};

// `points` in the world, the camera pose (z forward) for the projection. Throws kInvalidArgument for fewer than 3
// points or a degenerate projection (every triangle dropped).
TriangleMesh DelaunayBaseline(const std::vector<Vec3>& points, const Pose& camera_pose, const DelaunayParams& params);

}  // namespace graspsim
