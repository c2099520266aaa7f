// Surface normals of an unorganized point cloud (PAPERS.md part C, "Surface"): at each point the normal of the
// least-squares plane through its k nearest neighbours (the eigenvector of the smallest eigenvalue of their
// covariance), flipped to face the viewpoint, because a camera sees only surfaces that face it.
#pragma once

#include <vector>

#include "core/math.h"
#include "perception/neighbor_grid.h"
#include "perception/observation.h"

namespace graspsim {

struct NormalEstimationParams {
  int k = 10;                    // neighbours in each plane fit (the point itself included), 3..100
  Vec3 viewpoint = Vec3::Zero(); // m, in the cloud's frame: the camera centre
};

// Unit normals, one per point, n · (viewpoint − p) ≥ 0. Throws Error(kInvalidArgument) naming the field for an
// empty cloud, a non-finite point or viewpoint, k outside 3..100, or a cloud with fewer than 3 points.
std::vector<Vec3> EstimateNormals(const std::vector<Vec3>& points, const NormalEstimationParams& params);
// The same with the neighbours given (a grid or the image the points came from, image_neighbors.h).
std::vector<Vec3> EstimateNormals(const std::vector<Vec3>& points, const CloudNeighbors& neighbors,
                                  const NormalEstimationParams& params);

}  // namespace graspsim

namespace graspsim {

// Normals of the points of a depth image: at each point the plane fit over the points seen within a square window
// of pixels around it whose side spans about 2 radius_m on the surface at depth_m (at least 3 × 3 pixels; the
// points' median depth, MedianDepth in observation.h: a table-top object's depth varies by ~10 %), instead of over
// its k nearest in space. A depth camera's noise along the rays (~1 mm) exceeds its
// pixel spacing at table-top range (~0.3–0.5 mm), so the k nearest in space are picked by their noise as much as by
// their place and their plane tilts with it (normals_test.cpp: 39° mean error against 3°; at 39k points per view
// the completions came out less accurate than from the voxel-averaged cloud); pixels pick neighbours by place
// alone. The window's sums slide along the rows and columns: O(1) per point whatever the window. points[i] was
// seen at pixel pixels[i] of observation's image (at most one point per pixel); viewpoint as above; radius_m and
// depth_m > 0.
// A window with fewer than 3 points falls back to the k = 10 plane fit in space.
std::vector<Vec3> EstimateImageNormals(const Observation& observation, const std::vector<Vec3>& points,
                                       const std::vector<uint32_t>& pixels, double radius_m, double depth_m,
                                       const Vec3& viewpoint);

}  // namespace graspsim
