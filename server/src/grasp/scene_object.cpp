#include "grasp/scene_object.h"

#include <algorithm>
#include <limits>

#include "collision/tessellation.h"
#include "core/error.h"

namespace graspsim::grasp {
namespace {

// A geometry's bounding box in its own frame.
LinkBox GeometryBox(const Geometry& g) {
  LinkBox box;
  switch (g.kind) {
    case Geometry::Kind::kBox: box.half = 0.5 * g.box_size; break;
    case Geometry::Kind::kSphere: box.half = Vec3::Constant(g.radius); break;
    case Geometry::Kind::kCylinder: box.half = Vec3(g.radius, g.radius, 0.5 * g.length); break;
    case Geometry::Kind::kMesh: {
      Vec3 lo = Vec3::Constant(std::numeric_limits<double>::infinity()), hi = -lo;
      for (const auto& v : g.mesh->vertices) lo = lo.cwiseMin(v.cast<double>()), hi = hi.cwiseMax(v.cast<double>());
      box.centre = 0.5 * (lo + hi);
      box.half = 0.5 * (hi - lo);
      break;
    }
  }
  return box;
}

collision::LocalMesh GeometryMesh(const Geometry& g) {
  switch (g.kind) {
    case Geometry::Kind::kBox: return collision::BoxMesh(0.5 * g.box_size);
    case Geometry::Kind::kSphere: return collision::SphereMesh(g.radius);
    case Geometry::Kind::kCylinder: return collision::CylinderMesh(g.radius, 0.5 * g.length);
    case Geometry::Kind::kMesh: {
      collision::LocalMesh local;
      for (const auto& v : g.mesh->vertices) local.vertices.push_back(v.cast<double>());
      local.triangles = g.mesh->triangles;
      return local;
    }
  }
  return {};
}

}  // namespace

SceneObject ObjectFromScene(const SceneModel& model, const SceneState& state, const std::string& field,
                            const std::string& body_id, const std::vector<std::string>& skip_robots) {
  const auto found = model.body_index.find(body_id);
  if (found == model.body_index.end()) ThrowNotFound(field + ": no body '" + body_id.substr(0, 80) + "' in the scene");
  const BodySpec& body = model.bodies[found->second];
  if (body.collision.empty()) ThrowInvalidArgument(field + ": body '" + body_id + "' has no collision geometry");
  SceneObject out;
  out.pose = state.body_poses[found->second];
  auto mesh = std::make_shared<TriangleMesh>();
  for (const Geometry& g : body.collision) {
    const collision::LocalMesh local = GeometryMesh(g);
    const uint32_t base = static_cast<uint32_t>(mesh->vertices.size());
    for (const Vec3& v : local.vertices) mesh->vertices.push_back((g.origin * v).cast<float>());
    for (const auto& t : local.triangles) mesh->triangles.push_back({t[0] + base, t[1] + base, t[2] + base});
  }
  out.mesh = std::move(mesh);
  const Pose to_object = out.pose.Inverse();
  for (size_t b = 0; b < model.bodies.size(); ++b) {
    if (b == found->second) continue;
    if (!model.bodies[b].robot_id.empty() &&
        std::find(skip_robots.begin(), skip_robots.end(), model.bodies[b].robot_id) != skip_robots.end()) {
      continue;
    }
    const Pose in_object = to_object * state.body_poses[b];
    for (const Geometry& g : model.bodies[b].collision) {
      const LinkBox local = GeometryBox(g);
      const Pose placed = in_object * g.origin;
      out.obstacles.push_back({placed * local.centre, placed.orientation.toRotationMatrix() * local.axes, local.half});
    }
  }
  return out;
}

}  // namespace graspsim::grasp
