// SDF links → bodies (sdf_internal.h): collision geometry, including the shapes graspsim builds from its own
// primitives (primitive_shapes.h), and the file's inertials as stated.
#include <map>
#include <string>
#include <utility>
#include <vector>

#include "core/error.h"
#include "core/format.h"
#include "import/sdf_internal.h"
#include "import/primitive_shapes.h"

namespace graspsim::import {

void SdfRepairs::Warn(const std::string& element, const std::string& value, const std::string& action) {
  if (strict_) {
    ThrowInvalidArgument(element + " " + value + ": strict loading refuses what would need a repair (" + action + ")");
  }
  warnings_->push_back({element, value, action});
}

namespace {

void ConvertCollision(const sdf::Collision& collision, const Pose& origin, const std::string& field, MeshFiles* meshes,
                      SdfRepairs* repairs, BodySpec* body) {
  const sdf::Geometry& geometry = *collision.Geom();
  Geometry g;
  g.origin = origin;
  switch (geometry.Type()) {
    case sdf::GeometryType::BOX: {
      g.kind = Geometry::Kind::kBox;
      g.box_size = ToVec3(geometry.BoxShape()->Size());
      for (int axis = 0; axis < 3; ++axis) CheckPositive(field + " box size", g.box_size[axis]);
      break;
    }
    case sdf::GeometryType::SPHERE:
      g.kind = Geometry::Kind::kSphere;
      g.radius = geometry.SphereShape()->Radius();
      CheckPositive(field + " sphere radius", g.radius);
      break;
    case sdf::GeometryType::CYLINDER:
      g.kind = Geometry::Kind::kCylinder;
      g.radius = geometry.CylinderShape()->Radius();
      g.length = geometry.CylinderShape()->Length();
      CheckPositive(field + " cylinder radius", g.radius);
      CheckPositive(field + " cylinder length", g.length);
      break;
    case sdf::GeometryType::CAPSULE: {
      const double radius = geometry.CapsuleShape()->Radius(), length = geometry.CapsuleShape()->Length();
      CheckPositive(field + " capsule radius", radius);
      CheckNonNegative(field + " capsule length", length);
      if (length == 0) {
        g.kind = Geometry::Kind::kSphere;
        g.radius = radius;
        break;
      }
      for (Geometry& part : CapsuleGeometries(radius, length, origin)) body->collision.push_back(part);
      return;
    }
    case sdf::GeometryType::ELLIPSOID: {
      const Vec3 radii = ToVec3(geometry.EllipsoidShape()->Radii());
      for (int axis = 0; axis < 3; ++axis) CheckPositive(field + " ellipsoid radii", radii[axis]);
      g.kind = Geometry::Kind::kMesh;
      g.mesh = EllipsoidMesh(radii);
      break;
    }
    case sdf::GeometryType::PLANE: {
      const Vec3 normal = ToVec3(geometry.PlaneShape()->Normal());
      const double sx = geometry.PlaneShape()->Size().X(), sy = geometry.PlaneShape()->Size().Y();
      CheckFinite(field + " plane normal", normal);
      if (normal.norm() < 1e-9) ThrowInvalidArgument(field + " plane normal has zero length");
      CheckPositive(field + " plane size", sx);
      CheckPositive(field + " plane size", sy);
      repairs->Warn(field + " plane", FormatNumber(sx) + " x " + FormatNumber(sy) + " m",
           "a box of that size, " + FormatNumber(kPlaneThickness) + " m thick below the plane");
      g = PlaneBox(normal, sx, sy, origin);
      break;
    }
    case sdf::GeometryType::MESH: {
      const sdf::Mesh& mesh = *geometry.MeshShape();
      const Vec3 scale = ToVec3(mesh.Scale());
      CheckFinite(field + " mesh scale", scale);
      if (!mesh.Submesh().empty()) {
        repairs->Warn(field + " mesh submesh", Quoted(mesh.Submesh()), "the whole mesh file is used");
      }
      const std::string uri = mesh.Uri();
      g.kind = Geometry::Kind::kMesh;
      if (!meshes->Load(field + " mesh " + Quoted(uri), uri, MeshPathCandidates(uri), scale, &g)) return;  // listed later
      break;
    }
    case sdf::GeometryType::EMPTY:
      return;
    default:  // heightmap, polyline
      repairs->Warn(field + " geometry", "heightmap or polyline", "left out: graspsim has no such shape");
      return;
  }
  body->collision.push_back(std::move(g));
}

}  // namespace

BodySpec ConvertSdfLink(const sdf::Link& link, const std::string& name, const std::string& field,
                        MeshFiles* meshes, SdfRepairs* repairs) {
  BodySpec body;
  body.id = name;
  body.motion = BodyMotion::kArticulated;
  // The collisions are read from the element: libsdformat's Link drops a collision whose name repeats (an error
  // it reports) and PyBullet keeps them all (kiva_shelf/model.sdf has 21 named "pod_collision").
  std::map<std::string, int> seen;
  for (sdf::ElementPtr e = link.Element()->FindElement("collision"); e != nullptr;
       e = e->GetNextElement("collision")) {
    const sdf::ParamPtr name_attribute = e->GetAttribute("name");
    const std::string collision_name = name_attribute != nullptr ? name_attribute->GetAsString() : "";
    const std::string collision_field = field + " collision " + Quoted(collision_name);
    const sdf::Collision* parsed = link.CollisionByName(collision_name);
    Pose origin;
    sdf::Collision loaded;
    if (parsed != nullptr && parsed->Element() == e) {
      ignition::math::Pose3d pose;
      const sdf::Errors errors = parsed->SemanticPose().Resolve(pose, "");
      if (!errors.empty()) ThrowInvalidArgument(collision_field + " pose: " + Describe(errors[0]));
      origin = ToPose(pose, collision_field + " pose");
    } else {
      const sdf::Errors errors = loaded.Load(e);
      if (!errors.empty()) ThrowInvalidArgument(collision_field + ": " + Describe(errors[0]));
      if (!loaded.PoseRelativeTo().empty()) {
        ThrowInvalidArgument(collision_field + " pose relative_to " + Quoted(loaded.PoseRelativeTo()) +
                             ": a collision whose name repeats must give its pose in the link frame");
      }
      origin = ToPose(loaded.RawPose(), collision_field + " pose");
      parsed = &loaded;
    }
    if (++seen[collision_name] == 2) {
      repairs->Warn(collision_field, "(name repeated)", "every collision of that name kept, as PyBullet does");
    }
    ConvertCollision(*parsed, origin, collision_field, meshes, repairs, &body);
  }
  return body;
}

void ReadSdfInertial(const sdf::Link& link, const std::string& name, const std::string& field,
                     FileInertials* inertials) {
  // libsdformat defaults a missing <inertial> to 1 kg and a unit tensor: absence is read from the element.
  const sdf::ElementPtr element = link.Element();
  if (!element->HasElement("inertial")) return;
  const sdf::ElementPtr inertial = element->FindElement("inertial");
  FileInertial file;
  file.field = field + " inertial";
  file.mass = inertial->Get<double>("mass");
  file.origin = ToPose(inertial->Get<ignition::math::Pose3d>("pose"), file.field + " pose");
  if (const sdf::ElementPtr tensor = inertial->FindElement("inertia"); tensor != nullptr) {
    const double ixx = tensor->Get<double>("ixx"), iyy = tensor->Get<double>("iyy"), izz = tensor->Get<double>("izz");
    const double ixy = tensor->Get<double>("ixy"), ixz = tensor->Get<double>("ixz"), iyz = tensor->Get<double>("iyz");
    file.inertia << ixx, ixy, ixz, ixy, iyy, iyz, ixz, iyz, izz;
  } else {
    file.inertia = Mat3::Identity();  // SDF's default <inertia>
  }
  (*inertials)[name] = file;
}

}  // namespace graspsim::import
