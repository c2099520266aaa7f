#include "core/mesh.h"

#include <cmath>

#include "core/error.h"

namespace graspsim {

void ValidateMesh(const TriangleMesh& mesh, const std::string& field, size_t max_triangles) {
  if (mesh.triangles.empty() || mesh.vertices.empty()) {
    ThrowInvalidArgument(field + ": mesh is empty (" + std::to_string(mesh.vertices.size()) + " vertices, " +
                         std::to_string(mesh.triangles.size()) + " triangles)");
  }
  if (mesh.triangles.size() > max_triangles) {
    ThrowResourceExhausted(field + ": mesh has " + std::to_string(mesh.triangles.size()) +
                           " triangles, above the limit of " + std::to_string(max_triangles));
  }
  for (size_t i = 0; i < mesh.vertices.size(); ++i) {
    if (!mesh.vertices[i].allFinite()) {
      ThrowInvalidArgument(field + ": vertex " + std::to_string(i) + " is not finite");
    }
  }
  const size_t n = mesh.vertices.size();
  for (size_t t = 0; t < mesh.triangles.size(); ++t) {
    for (uint32_t index : mesh.triangles[t]) {
      if (index >= n) {
        ThrowInvalidArgument(field + ": triangle " + std::to_string(t) + " has vertex index " +
                             std::to_string(index) + ", out of range for " + std::to_string(n) + " vertices");
      }
    }
  }
}

void MeshBounds(const TriangleMesh& mesh, Eigen::Vector3f* min, Eigen::Vector3f* max) {
  *min = Eigen::Vector3f::Constant(INFINITY);
  *max = Eigen::Vector3f::Constant(-INFINITY);
  for (const auto& v : mesh.vertices) {
    *min = min->cwiseMin(v);
    *max = max->cwiseMax(v);
  }
}

SolidProperties ComputeSolidProperties(const TriangleMesh& mesh) {
  // About a reference point inside the bounds (the vertices' mean) to keep the digits.
  Vec3 reference = Vec3::Zero();
  for (const auto& v : mesh.vertices) reference += v.cast<double>();
  if (!mesh.vertices.empty()) reference /= double(mesh.vertices.size());
  double volume = 0;
  Vec3 first = Vec3::Zero();
  Mat3 second = Mat3::Zero();
  for (const auto& t : mesh.triangles) {
    const Vec3 a = mesh.vertices[t[0]].cast<double>() - reference, b = mesh.vertices[t[1]].cast<double>() - reference,
               c = mesh.vertices[t[2]].cast<double>() - reference;
    const double v = a.dot(b.cross(c)) / 6;
    const Vec3 s = a + b + c;
    volume += v;
    first += v * s / 4;
    second += v / 20 * (a * a.transpose() + b * b.transpose() + c * c.transpose() + s * s.transpose());
  }
  SolidProperties out;
  out.volume = volume;
  if (volume == 0) return out;
  const Vec3 centre = first / volume;
  out.centroid = reference + centre;
  out.second_moment = second - volume * centre * centre.transpose();
  return out;
}

}  // namespace graspsim
