// Bodies the C++ suites build their worlds from.
#pragma once

#include <string>

#include "world/model.h"

namespace graspsim::test_objects {

// A box of uniform density (free by default): inertia m (b² + c²) / 12 about each axis.
inline BodySpec UniformBox(const std::string& id, const Vec3& size, double mass,
                           BodyMotion motion = BodyMotion::kFree) {
  BodySpec box;
  box.id = id;
  box.motion = motion;
  Geometry geometry;
  geometry.box_size = size;
  box.collision.push_back(geometry);
  box.inertial.mass = mass;
  const Vec3 s2 = size.cwiseProduct(size);
  box.inertial.inertia = Vec3(s2.y() + s2.z(), s2.x() + s2.z(), s2.x() + s2.y()).asDiagonal() * (mass / 12);
  return box;
}

}  // namespace graspsim::test_objects
