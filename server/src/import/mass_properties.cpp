#include "import/mass_properties.h"

#include <cmath>

namespace graspsim {
namespace {

// The inertia tensor of a body whose second moment (covariance) about a point is C: I = tr(C) 1 − C.
Mat3 InertiaFromCovariance(const Mat3& covariance) {
  return covariance.trace() * Mat3::Identity() - covariance;
}

SolidVolume MeshVolume(const TriangleMesh& mesh) {
  const SolidProperties solid = ComputeSolidProperties(mesh);
  SolidVolume result;
  if (!(std::abs(solid.volume) > 1e-15)) return result;  // open or flat: no enclosed volume
  const double sign = solid.volume < 0 ? -1.0 : 1.0;     // a mesh wound inside out
  result.volume = sign * solid.volume;
  result.centroid = solid.centroid;
  result.inertia_per_density = InertiaFromCovariance(sign * solid.second_moment);
  return result;
}

SolidVolume LocalVolume(const Geometry& g) {
  SolidVolume s;
  switch (g.kind) {
    case Geometry::Kind::kBox: {
      const Vec3& d = g.box_size;
      s.volume = d.prod();
      s.inertia_per_density = (s.volume / 12.0 * Vec3(d.y() * d.y() + d.z() * d.z(), d.x() * d.x() + d.z() * d.z(),
                                                       d.x() * d.x() + d.y() * d.y()))
                                  .asDiagonal();
      break;
    }
    case Geometry::Kind::kSphere:
      s.volume = 4.0 / 3.0 * M_PI * std::pow(g.radius, 3);
      s.inertia_per_density = Mat3::Identity() * 0.4 * s.volume * g.radius * g.radius;
      break;
    case Geometry::Kind::kCylinder: {
      const double r2 = g.radius * g.radius, l2 = g.length * g.length;
      s.volume = M_PI * r2 * g.length;
      const double across = s.volume * (3 * r2 + l2) / 12.0;
      s.inertia_per_density = Vec3(across, across, s.volume * r2 / 2.0).asDiagonal();
      break;
    }
    case Geometry::Kind::kMesh:
      if (g.mesh != nullptr) s = MeshVolume(*g.mesh);
      break;
  }
  return s;
}

}  // namespace

SolidVolume VolumeOf(const Geometry& geometry) {
  SolidVolume local = LocalVolume(geometry);
  const Mat3 R = geometry.origin.orientation.toRotationMatrix();
  local.centroid = geometry.origin * local.centroid;
  local.inertia_per_density = R * local.inertia_per_density * R.transpose();
  return local;
}

Inertial SolidMassProperties(const std::vector<Geometry>& geometry, double density) {
  std::vector<SolidVolume> parts;
  double volume = 0;
  Vec3 moment = Vec3::Zero();
  for (const Geometry& g : geometry) {
    parts.push_back(VolumeOf(g));
    volume += parts.back().volume;
    moment += parts.back().volume * parts.back().centroid;
  }
  Inertial result;
  if (!(volume > 0) || !(density > 0)) return result;
  result.mass = density * volume;
  result.center_of_mass = moment / volume;
  for (const SolidVolume& part : parts) {
    const Vec3 d = part.centroid - result.center_of_mass;  // parallel axis: + V (|d|² 1 − d dᵀ)
    result.inertia += density * (part.inertia_per_density +
                                 part.volume * (d.squaredNorm() * Mat3::Identity() - d * d.transpose()));
  }
  result.inertia = 0.5 * (result.inertia + result.inertia.transpose()).eval();
  return result;
}

}  // namespace graspsim
