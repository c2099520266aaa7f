// Math types of the engine (Eigen, double precision). Poses are rigid transforms; quaternions are (w, x, y, z).
#pragma once

#include <Eigen/Geometry>

namespace graspsim {

using Vec3 = Eigen::Vector3d;
using Mat3 = Eigen::Matrix3d;
using Quat = Eigen::Quaterniond;
using Vec6 = Eigen::Matrix<double, 6, 1>;

// A rigid transform x_parent = orientation * x_child + position.
struct Pose {
  Vec3 position = Vec3::Zero();
  Quat orientation = Quat::Identity();

  Pose operator*(const Pose& child) const {
    return {position + orientation * child.position, (orientation * child.orientation).normalized()};
  }
  Vec3 operator*(const Vec3& point) const { return position + orientation * point; }
  Pose Inverse() const {
    const Quat inv = orientation.conjugate();
    return {-(inv * position), inv};
  }
};

// [top; bottom]. (Eigen's comma initialiser goes through dynamic-size blocks: several times slower in hot loops.)
inline Vec6 Stack(const Vec3& top, const Vec3& bottom) {
  Vec6 out;
  out.head<3>() = top;
  out.tail<3>() = bottom;
  return out;
}

// The cross-product matrix: Skew(w) x = w × x.
inline Mat3 Skew(const Vec3& w) {
  Mat3 m;
  m << 0, -w.z(), w.y(), w.z(), 0, -w.x(), -w.y(), w.x(), 0;
  return m;
}

// Rotation from URDF roll-pitch-yaw (fixed axes x, then y, then z), rad.
inline Quat QuatFromRpy(double roll, double pitch, double yaw) {
  return Quat(Eigen::AngleAxisd(yaw, Vec3::UnitZ()) * Eigen::AngleAxisd(pitch, Vec3::UnitY()) *
              Eigen::AngleAxisd(roll, Vec3::UnitX()));
}

}  // namespace graspsim
