// A pinhole depth camera for the shape-completion tests: exact ray casts against analytic solids (an oriented box,
// an upright cylinder, a sphere), giving the depth image and the object mask a segmented camera view would.
#pragma once

#include <cmath>
#include <functional>
#include <limits>
#include <optional>
#include <vector>

#include "core/math.h"
#include "perception/observation.h"

namespace graspsim::test_render {

// Camera at `eye` looking at `target`, world z up (camera: z forward, x right, y down).
inline Pose LookAt(const Vec3& eye, const Vec3& target) {
  const Vec3 forward = (target - eye).normalized();
  const Vec3 right = forward.cross(Vec3::UnitZ()).normalized();
  const Vec3 down = forward.cross(right);
  Mat3 r;
  r.col(0) = right;
  r.col(1) = down;
  r.col(2) = forward;
  return {eye, Quat(r)};
}

// Distance along a unit ray to the first hit (nullopt: none). Local solids centred at the origin.
using Solid = std::function<std::optional<double>(const Vec3& origin, const Vec3& direction)>;

inline Solid Box(const Vec3& size, const Pose& pose) {
  return [size, pose](const Vec3& o, const Vec3& d) -> std::optional<double> {
    const Pose inv = pose.Inverse();
    const Vec3 lo = inv * o, ld = inv.orientation * d;
    double t0 = 0, t1 = std::numeric_limits<double>::infinity();
    for (int a = 0; a < 3; ++a) {
      if (std::abs(ld[a]) < 1e-15) {
        if (std::abs(lo[a]) > size[a] / 2) return std::nullopt;
        continue;
      }
      double ta = (-size[a] / 2 - lo[a]) / ld[a], tb = (size[a] / 2 - lo[a]) / ld[a];
      if (ta > tb) std::swap(ta, tb);
      t0 = std::max(t0, ta);
      t1 = std::min(t1, tb);
    }
    if (t0 > t1 || t0 <= 0) return std::nullopt;
    return t0;
  };
}

// Upright (z) cylinder of radius r and height h centred at `centre`.
inline Solid Cylinder(double r, double h, const Vec3& centre) {
  return [r, h, centre](const Vec3& o_world, const Vec3& d) -> std::optional<double> {
    const Vec3 o = o_world - centre;
    std::optional<double> best;
    const double a = d.x() * d.x() + d.y() * d.y(), b = 2 * (o.x() * d.x() + o.y() * d.y());
    const double c = o.x() * o.x() + o.y() * o.y() - r * r, disc = b * b - 4 * a * c;
    if (a > 1e-15 && disc >= 0) {
      const double t = (-b - std::sqrt(disc)) / (2 * a);
      if (t > 0 && std::abs(o.z() + t * d.z()) <= h / 2) best = t;
    }
    for (double cap : {-h / 2, h / 2}) {
      if (std::abs(d.z()) < 1e-15) continue;
      const double t = (cap - o.z()) / d.z();
      const Vec3 p = o + t * d;
      if (t > 0 && p.x() * p.x() + p.y() * p.y() <= r * r && (!best || t < *best)) best = t;
    }
    return best;
  };
}

// A cup: the upright cylinder (r, h, centre) with a bore of radius `bore` open at the top, `floor` thick at the
// bottom. Both solids are convex, so a ray meets each over one interval; the cup's first point is where the ray
// enters the outer one, unless that lies inside the bore, where it is the ray's exit from the bore (the inner wall
// or the floor).
inline Solid Cup(double r, double h, double bore, double floor, const Vec3& centre) {
  const Solid outer = Cylinder(r, h, centre);
  // The bore runs from the floor to 1 cm above the rim, so the top is open.
  const double bore_h = h - floor + 0.01;
  const Solid inner = Cylinder(bore, bore_h, centre + Vec3(0, 0, floor - h / 2 + bore_h / 2));
  const auto exit = [](const Solid& solid, const Vec3& o, const Vec3& d) {
    constexpr double kFar = 100;  // m, beyond the scene: cast back from there
    const std::optional<double> back = solid(o + kFar * d, -d);
    return back ? kFar - *back : 0.0;
  };
  return [=](const Vec3& o, const Vec3& d) -> std::optional<double> {
    const std::optional<double> enter = outer(o, d), enter_bore = inner(o, d);
    if (!enter || !enter_bore || *enter < *enter_bore) return enter;
    const double leave_bore = exit(inner, o, d);
    if (*enter >= leave_bore) return enter;
    if (leave_bore < exit(outer, o, d)) return leave_bore;
    return std::nullopt;
  };
}

inline Solid Sphere(double r, const Vec3& centre) {
  return [r, centre](const Vec3& o, const Vec3& d) -> std::optional<double> {
    const Vec3 oc = o - centre;
    const double b = oc.dot(d), c = oc.squaredNorm() - r * r, disc = b * b - c;
    if (disc < 0) return std::nullopt;
    const double t = -b - std::sqrt(disc);
    return t > 0 ? std::optional<double>(t) : std::nullopt;
  };
}

// Depth (z along the optical axis) and mask of one solid; `noise(u, v)` adds to each depth (m).
inline DepthImage Render(const Solid& solid, const Pose& camera, const CameraIntrinsics& k,
                         const std::function<double(int, int)>& noise = {}) {
  DepthImage image;
  image.intrinsics = k;
  image.depth.assign(size_t(k.width) * k.height, std::numeric_limits<float>::quiet_NaN());
  image.mask.assign(image.depth.size(), 0);
  const Mat3 r = camera.orientation.toRotationMatrix();
  for (int v = 0; v < k.height; ++v) {
    for (int u = 0; u < k.width; ++u) {
      const Vec3 ray_camera((u - k.cx) / k.fx, (v - k.cy) / k.fy, 1.0);
      const Vec3 direction = (r * ray_camera).normalized();
      const std::optional<double> t = solid(camera.position, direction);
      if (!t) continue;
      const double z = *t / ray_camera.norm();
      const size_t i = size_t(v) * k.width + u;
      image.depth[i] = float(z + (noise ? noise(u, v) : 0.0));
      image.mask[i] = 1;
    }
  }
  return image;
}

}  // namespace graspsim::test_render
