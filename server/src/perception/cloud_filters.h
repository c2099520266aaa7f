// Point-cloud clean-up before the symmetry search (PAPERS.md part C, "Surface: filter outliers"): statistical
// outlier removal and voxel down-sampling. Both keep the input order of what they keep (deterministic).
#pragma once

#include <vector>

#include "core/math.h"

namespace graspsim {

// PCL's StatisticalOutlierRemoval: a point's mean distance to its k nearest neighbours (itself excluded) against
// the mean μ and standard deviation σ of that figure over the cloud; points beyond μ + std_ratio σ go.
// k in 1..100, std_ratio > 0; a cloud of at most k points is returned as it is.
std::vector<Vec3> RemoveStatisticalOutliers(const std::vector<Vec3>& points, int k, double std_ratio);

// One point per occupied cube of side `voxel` (m, > 0): the mean of its points, in the order the cubes were
// first met.
std::vector<Vec3> VoxelDownsample(const std::vector<Vec3>& points, double voxel);

}  // namespace graspsim
