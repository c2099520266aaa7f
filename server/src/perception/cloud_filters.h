// Point-cloud clean-up before the symmetry search (PAPERS.md part C, "Surface: filter outliers"): statistical
// outlier removal and voxel down-sampling. Both keep the input order of what they keep (deterministic).
#pragma once

#include <cstdint>
#include <vector>

#include "core/math.h"
#include "perception/neighbor_grid.h"

namespace graspsim {

// PCL's StatisticalOutlierRemoval: a point's mean distance to its k nearest neighbours (itself excluded) against
// the mean μ and standard deviation σ of that figure over the cloud; points beyond μ + std_ratio σ go.
// k in 1..100, std_ratio > 0; a cloud of at most k points is returned as it is.
std::vector<Vec3> RemoveStatisticalOutliers(const std::vector<Vec3>& points, int k, double std_ratio);
// The same test with the neighbours given (a grid or the image the points came from): the indices of the points it
// keeps, ascending.
std::vector<uint32_t> StatisticalInliers(const std::vector<Vec3>& points, const CloudNeighbors& neighbors, int k,
                                         double std_ratio);

// The cube of side `voxel` (m, > 0; the cubes' corners at origin + voxel × integers) each point falls in, numbered
// in the order the cubes are first met: (*group)[i] for point i. Returns the number of cubes.
size_t VoxelGroups(const std::vector<Vec3>& points, double voxel, const Vec3& origin, std::vector<uint32_t>* group);

// One point per occupied cube of side `voxel` (m, > 0): the mean of its points, in the order the cubes were
// first met. `lone_source`, when given, receives per output point the index of its input point when the cube held
// only that one, else −1 (a cube far below the points' spacing keeps every point as it was, and where it came from).
std::vector<Vec3> VoxelDownsample(const std::vector<Vec3>& points, double voxel,
                                  std::vector<int64_t>* lone_source = nullptr);

// The eigenvalues of the points' covariance (unnormalized: the sum of (p − mean)(p − mean)ᵀ), ascending: how far
// the cloud spreads along its three principal axes; a surface needs two. Non-empty, finite points.
Vec3 SpreadEigenvalues(const std::vector<Vec3>& points);

}  // namespace graspsim
