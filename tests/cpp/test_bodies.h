// Bodies the C++ suites build their worlds from.
#pragma once

#include <optional>
#include <string>
#include <utility>

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

// A robot joint "<robot>/<name>" between two links, its axis normalised, limits ±10 (rad or m) so a simulation
// never clamps it; optionally following another (mimic).
inline JointSpec RobotJoint(const std::string& id, JointType type, const std::string& parent, const std::string& child,
                            const Pose& origin, const Vec3& axis, std::optional<MimicSpec> mimic = std::nullopt) {
  JointSpec joint;
  joint.id = id;
  joint.robot_id = id.substr(0, id.find('/'));
  joint.type = type;
  joint.parent_body = parent;
  joint.child_body = child;
  joint.origin = origin;
  joint.axis = axis.normalized();
  joint.lower = -10;
  joint.upper = 10;
  joint.mimic = std::move(mimic);
  return joint;
}

}  // namespace graspsim::test_objects
