#include "collision/distance_grid.h"

#include <cmath>

#include "collision/mesh_query.h"

namespace graspsim {

DistanceGrid::DistanceGrid(std::shared_ptr<const TriangleMesh> mesh, double cell, double padding)
    : padding_(padding) {
  Vec3 lo = Vec3::Constant(INFINITY), hi = Vec3::Constant(-INFINITY);
  for (const auto& v : mesh->vertices) {
    lo = lo.cwiseMin(v.cast<double>());
    hi = hi.cwiseMax(v.cast<double>());
  }
  lo.array() -= padding;
  hi.array() += padding;
  for (;;) {
    nx_ = static_cast<int>(std::ceil((hi.x() - lo.x()) / cell)) + 1;
    ny_ = static_cast<int>(std::ceil((hi.y() - lo.y()) / cell)) + 1;
    nz_ = static_cast<int>(std::ceil((hi.z() - lo.z()) / cell)) + 1;
    if (static_cast<size_t>(nx_) * ny_ * nz_ <= (size_t{1} << 21)) break;
    cell *= 1.25;
  }
  cell_ = cell;
  origin_ = lo;
  last_ = Vec3(nx_ - 1, ny_ - 1, nz_ - 1);
  half_diagonal_ = 0.5 * std::sqrt(3.0) * cell;
  const collision::MeshBvh bvh(std::move(mesh));
  const double reach = 2 * (hi - lo).norm();  // every node finds its closest point
  values_.resize(static_cast<size_t>(nx_) * ny_ * nz_);
  size_t index = 0;
  for (int k = 0; k < nz_; ++k) {
    for (int j = 0; j < ny_; ++j) {
      for (int i = 0; i < nx_; ++i) {
        double depth = 0;
        Vec3 normal;
        bvh.Depth(origin_ + cell * Vec3(i, j, k), reach, &depth, &normal);
        // Signed distance = −depth, rounded toward −∞ so the float never overstates the clearance.
        values_[index++] = std::nextafter(static_cast<float>(-depth), -INFINITY);
      }
    }
  }
}

}  // namespace graspsim
