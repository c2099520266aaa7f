#include "perception/normals.h"

#include <Eigen/Eigenvalues>

#include "core/error.h"
#include "core/format.h"
#include "core/validate.h"
#include "perception/neighbor_grid.h"

namespace graspsim {

std::vector<Vec3> EstimateNormals(const std::vector<Vec3>& points, const NormalEstimationParams& params) {
  if (points.size() < 3) {
    ThrowInvalidArgument("points: " + std::to_string(points.size()) + " points; a plane fit needs at least 3");
  }
  if (params.k < 3 || params.k > 100) {
    ThrowInvalidArgument("k: " + std::to_string(params.k) + " is outside 3..100");
  }
  CheckFinite("viewpoint", params.viewpoint);
  for (size_t i = 0; i < points.size(); ++i) {
    if (!points[i].allFinite()) CheckFinite("points[" + std::to_string(i) + "]", points[i]);  // names only a bad one
  }

  const NeighborGrid grid(points, NeighborGrid::SuggestCellSize(points, params.k));
  std::vector<Vec3> normals(points.size());
  std::vector<uint32_t> neighbours;
  for (size_t i = 0; i < points.size(); ++i) {
    grid.Nearest(points[i], params.k, &neighbours);
    // Covariance about the neighbours' mean, accumulated relative to the query point to keep the digits.
    Vec3 mean = Vec3::Zero();
    for (uint32_t j : neighbours) mean += points[j] - points[i];
    mean /= double(neighbours.size());
    Mat3 covariance = Mat3::Zero();
    for (uint32_t j : neighbours) {
      const Vec3 d = points[j] - points[i] - mean;
      covariance += d * d.transpose();
    }
    // The closed-form 3 × 3 solver (about 3× faster than the iterative one; the smallest eigenvector of a
    // neighbourhood this flat is well separated, and the covariance is relative to the point, so no digits lost).
    Eigen::SelfAdjointEigenSolver<Mat3> eigen;
    eigen.computeDirect(covariance);
    Vec3 n = eigen.eigenvectors().col(0);  // eigenvalues ascending: the direction of least spread
    if (n.dot(params.viewpoint - points[i]) < 0) n = -n;
    normals[i] = n.normalized();
  }
  return normals;
}

}  // namespace graspsim
