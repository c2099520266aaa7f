// Both directions of Bohg et al.'s mesh deviation, for the perception suites: uniform samples of the mesh
// against the exact distance to the true surface, and points of the true surface (a uniform sampling of it)
// against the mesh.
#pragma once

#include <cmath>
#include <functional>
#include <vector>

#include "core/math.h"
#include "core/mesh.h"
#include "perception/mesh_metrics.h"

namespace graspsim::test_shapes {

struct Deviation {
  double mesh_to_shape = 0, shape_to_mesh = 0;  // m, mean
  double Mean() const { return (mesh_to_shape + shape_to_mesh) / 2; }
};

inline Deviation Measure(const TriangleMesh& mesh, const std::function<double(const Vec3&)>& distance,
                         const std::vector<Vec3>& surface) {
  Deviation d;
  const std::vector<Vec3> samples = SampleSurface(mesh, 20000, 7);
  for (const Vec3& p : samples) d.mesh_to_shape += std::abs(distance(p));
  d.mesh_to_shape /= double(samples.size());
  const MeshDistance to_mesh(mesh);
  for (const Vec3& p : surface) d.shape_to_mesh += to_mesh.Distance(p);
  d.shape_to_mesh /= double(surface.size());
  return d;
}

}  // namespace graspsim::test_shapes
