// Surface normals of an unorganized point cloud (PAPERS.md part C, "Surface"): at each point the normal of the
// least-squares plane through its k nearest neighbours (the eigenvector of the smallest eigenvalue of their
// covariance), flipped to face the viewpoint, because a camera sees only surfaces that face it.
#pragma once

#include <vector>

#include "core/math.h"

namespace graspsim {

struct NormalEstimationParams {
  int k = 10;                    // neighbours in each plane fit (the point itself included), 3..100
  Vec3 viewpoint = Vec3::Zero(); // m, in the cloud's frame: the camera centre
};

// Unit normals, one per point, n · (viewpoint − p) ≥ 0. Throws Error(kInvalidArgument) naming the field for an
// empty cloud, a non-finite point or viewpoint, k outside 3..100, or a cloud with fewer than 3 points.
std::vector<Vec3> EstimateNormals(const std::vector<Vec3>& points, const NormalEstimationParams& params);

}  // namespace graspsim
