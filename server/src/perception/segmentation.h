// Table-top scene segmentation (PAPERS.md part C; issue 5, stage 1): the dominant plane by RANSAC is the table;
// the points above it are split into objects by Euclidean clustering (PCL's SACSegmentation and
// EuclideanClusterExtraction, in segmentation.cpp only).
#pragma once

#include <vector>

#include "core/math.h"

namespace graspsim {

struct SegmentationParams {
  double plane_threshold = 0.01;      // m: a point this close to the plane is table, (0, 1]
  double cluster_tolerance = 0.02;    // m: neighbours closer than this join one object, (0, 1]
  int min_cluster_points = 30;        // smaller clusters are dropped (noise), ≥ 1
  int ransac_iterations = 1000;       // 1..100000; RANSAC is seeded, so the answer is deterministic
};

struct SceneSegmentation {
  Vec3 table_normal = Vec3::UnitZ();  // unit, pointing to the side the objects are on
  double table_offset = 0;            // m: the table is {x : normal · x = offset}
  size_t table_points = 0;
  std::vector<std::vector<Vec3>> objects;  // above the table, largest first
};

// Throws kInvalidArgument naming the field: an empty cloud, non-finite points, parameters out of range, no plane
// found (fewer than 3 points, or all on a line).
SceneSegmentation SegmentScene(const std::vector<Vec3>& points, const SegmentationParams& params);

}  // namespace graspsim
