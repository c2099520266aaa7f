// A signed-distance grid of a closed triangle mesh, for fast conservative "is this ball clear of the mesh?"
// queries (the motion planner's obstacle test for mesh objects, server/src/motion). Built once per mesh with
// exact Embree queries (closest point + parity ray) at the grid nodes; looked up without Embree.
//
// Conservative lookup: the signed distance is 1-Lipschitz, so at a point p whose nearest node n is at most
// h√3/2 away (h the cell edge), distance(p) ≥ value(n) − h√3/2. Beyond the grid (which spans the mesh's bounds
// plus `padding`), distance(p) ≥ padding + the distance from p to the grid's box.
#pragma once

#include <memory>
#include <vector>

#include "core/math.h"
#include "core/mesh.h"

namespace graspsim {

class DistanceGrid {
 public:
  // `cell` m, > 0; the grid holds at most 2^21 nodes (the cell grows until it fits).
  DistanceGrid(std::shared_ptr<const TriangleMesh> mesh, double cell, double padding);

  // A lower bound of the signed distance from p (mesh frame, m) to the mesh surface: > 0 outside, < 0 inside.
  double LowerBound(const Vec3& p) const {
    const Vec3 g = (p - origin_) / cell_;
    const Vec3 clamped = g.cwiseMax(Vec3::Zero()).cwiseMin(last_);
    if (g != clamped) return padding_ + (g - clamped).norm() * cell_;
    const int i = static_cast<int>(clamped.x() + 0.5), j = static_cast<int>(clamped.y() + 0.5),
              k = static_cast<int>(clamped.z() + 0.5);
    return values_[(static_cast<size_t>(k) * ny_ + j) * nx_ + i] - half_diagonal_;
  }

  double cell() const { return cell_; }

 private:
  Vec3 origin_ = Vec3::Zero(), last_ = Vec3::Zero();
  double cell_ = 0, padding_ = 0, half_diagonal_ = 0;
  int nx_ = 0, ny_ = 0, nz_ = 0;
  std::vector<float> values_;  // rounded down to float
};

}  // namespace graspsim
