#include "edits/scene_edits.h"

#include "core/error.h"
#include "core/format.h"
#include "core/validate.h"
#include "edits/edit_codec.h"
#include "physics/engine.h"
#include "physics/simulation.h"

namespace graspsim::edits {
namespace {

// Built-in models carry no mesh files.
const std::string* NoFile(const std::string&) { return nullptr; }

FileLookup LookupIn(const std::map<std::string, StoredFile>& files) {
  return [&files](const std::string& path) -> const std::string* {
    auto it = files.find(path);
    return it == files.end() ? nullptr : it->second.bytes.get();
  };
}

const BuiltinModelInfo& FindBuiltin(const std::string& name, const std::string& kind) {
  for (const auto& info : BuiltinModels()) {
    if (info.name != name) continue;
    if (info.kind != kind) {
      ThrowInvalidArgument("builtin: '" + name + "' is a " + info.kind + " model; add it with " +
                           (info.kind == "robot" ? "AddRobot" : "AddObject"));
    }
    return info;
  }
  BuiltinModelUrdf(name);  // throws kNotFound listing the known models
  ThrowNotFound("builtin: '" + name + "' is not known");
}

Material WithSpec(const std::string& field, const MaterialSpec& spec, Material out) {
  if (spec.static_friction) out.static_friction = *spec.static_friction;
  if (spec.dynamic_friction) out.dynamic_friction = *spec.dynamic_friction;
  CheckNonNegative(field + ".dynamic_friction", out.dynamic_friction);
  CheckNonNegative(field + ".static_friction", out.static_friction);
  if (out.static_friction < out.dynamic_friction) {
    ThrowInvalidArgument(field + ": static_friction " + FormatNumber(out.static_friction) +
                         " is below dynamic_friction " + FormatNumber(out.dynamic_friction));
  }
  const std::pair<const char*, double> given[] = {
      {"contact_stiffness", spec.contact_stiffness}, {"contact_damping", spec.contact_damping},
      {"bristle_stiffness", spec.bristle_stiffness}, {"bristle_damping", spec.bristle_damping},
      {"viscous_friction", spec.viscous_friction},   {"stribeck_velocity", spec.stribeck_velocity}};
  for (const auto& [name, value] : given) CheckNonNegative(field + "." + name, value);
  out.contact_stiffness = spec.contact_stiffness;
  out.contact_damping = spec.contact_damping;
  out.bristle_stiffness = spec.bristle_stiffness;
  out.bristle_damping = spec.bristle_damping;
  out.viscous_friction = spec.viscous_friction;
  out.stribeck_velocity = spec.stribeck_velocity;
  return out;
}

}  // namespace

Geometry ShapeGeometry(const std::string& field, const ShapeSpec& shape, const FileLookup& files,
                       const Limits& limits) {
  Geometry out;
  out.kind = shape.kind;
  out.origin = shape.origin;
  CheckPose(field + ".origin", &out.origin);
  for (int i = 0; i < 3; ++i) CheckPositive(field + ".scale." + "xyz"[i], shape.scale[i]);
  switch (shape.kind) {
    case Geometry::Kind::kBox:
      for (int i = 0; i < 3; ++i) CheckPositive(field + ".box.size." + "xyz"[i], shape.box_size[i]);
      out.box_size = shape.box_size;
      break;
    case Geometry::Kind::kSphere:
      CheckPositive(field + ".sphere.radius", shape.radius);
      out.radius = shape.radius;
      break;
    case Geometry::Kind::kCylinder:
      CheckPositive(field + ".cylinder.radius", shape.radius);
      CheckPositive(field + ".cylinder.length", shape.length);
      out.radius = shape.radius;
      out.length = shape.length;
      break;
    case Geometry::Kind::kMesh:
      if (shape.mesh) {
        TriangleMesh mesh = *shape.mesh;
        ValidateMesh(mesh, field + ".mesh", limits.max_triangles_per_mesh);
        for (auto& v : mesh.vertices) v = v.cwiseProduct(shape.scale.cast<float>());
        out.mesh = std::make_shared<const TriangleMesh>(std::move(mesh));
        break;
      }
      CheckRelativePath(field + ".mesh_file", shape.mesh_file);
      const std::string* bytes = files(shape.mesh_file);
      if (!bytes) ThrowInvalidArgument(field + ".mesh_file: '" + shape.mesh_file + "' was not uploaded to this scene");
      out.mesh = LoadSharedMeshFile(field + ".mesh_file", shape.mesh_file, *bytes, shape.scale, limits);
      out.mesh_file = shape.mesh_file;
      break;
  }
  return out;
}

AddedObject AddObject(Scene* scene, const AddObjectEdit& edit, const Limits& limits) {
  CheckName("name", edit.name);
  Pose pose = edit.pose;
  CheckPose("pose", &pose);
  if (edit.shape.has_value() == !edit.builtin.empty()) ThrowInvalidArgument("source: give geometry or builtin");
  AddedObject result;
  BodySpec body;
  body.id = edit.name;
  body.motion = edit.is_static ? BodyMotion::kStatic : BodyMotion::kFree;
  if (edit.shape) {
    const auto files = scene->Files();  // meshes are parsed outside the scene's lock
    body.collision.push_back(ShapeGeometry("geometry", *edit.shape, LookupIn(files), limits));
    // A static body never moves: it needs no mass.
    if (!edit.inertial && !edit.is_static) {
      body.inertial = ObjectInertialFromGeometry("inertial", body.collision, edit.import_options, &result.warnings);
    }
  } else {
    const BuiltinModelInfo& info = FindBuiltin(edit.builtin, "object");
    RobotDescription model = LoadUrdf(BuiltinModelUrdf(info.name), NoFile, limits);
    body.collision = std::move(model.links.front().collision);
    body.inertial = model.links.front().inertial;
    if (info.is_static) body.motion = BodyMotion::kStatic;
  }
  if (edit.inertial) {
    CheckPositive("inertial.mass", edit.inertial->mass);
    CheckFinite("inertial.center_of_mass", edit.inertial->center_of_mass);
    CheckInertia("inertial", edit.inertial->inertia);
    body.inertial = *edit.inertial;
  }
  if (edit.material) body.material = WithSpec("material", *edit.material, body.material);
  const SceneOp op = EncodeEdit(edit);
  result.body = scene->AddObject(std::move(body), pose, &op);
  result.pose = pose;
  return result;
}

AddedRobotWithWarnings AddRobot(Scene* scene, const AddRobotEdit& edit, const Limits& limits) {
  CheckName("name", edit.name);
  Pose base_pose = edit.base_pose;
  CheckPose("base_pose", &base_pose);
  auto files = scene->Files();
  for (const auto& [path, bytes] : edit.files) {
    CheckRelativePath("files['" + path + "'].path", path);
    files[path] = {bytes, ""};
  }
  std::string source;
  ImportedRobot imported;
  switch (edit.format) {
    case RobotFormat::kUrdf:
      source = "urdf";
      imported = ImportUrdf(edit.source, LookupIn(files), edit.import_options, limits);
      break;
    case RobotFormat::kMjcf:
      source = "mjcf";
      imported = ImportMjcf(edit.source, LookupIn(files), edit.import_options, limits);
      break;
    case RobotFormat::kSdf:
      source = "sdf";
      imported = ImportSdf(edit.source, LookupIn(files), edit.import_options, limits);
      break;
    case RobotFormat::kBuiltin:
      source = "builtin:" + FindBuiltin(edit.source, "robot").name;
      imported.description = LoadUrdf(BuiltinModelUrdf(edit.source), LookupIn(files), limits);
      break;
  }
  const SceneOp op = EncodeEdit(edit);
  return {scene->AddRobot(edit.name, source, imported.description, base_pose, &op), imported.warnings};
}

std::vector<std::string> RemoveBody(Scene* scene, const RemoveBodyEdit& edit) {
  const SceneOp op = EncodeEdit(edit);
  return scene->Remove(edit.id, &op);
}

void SetSimulationParams(Scene* scene, const SetSimulationParamsEdit& edit) {
  ValidateSimulationParams(edit.params);
  CheckEngineSupports(*scene->View().model, edit.params.engine);  // the engine must simulate what the scene holds
  const SceneOp op = EncodeEdit(edit);
  scene->SetSimulationParams(edit.params, &op);
}

AddObjectEdit UniformSolidObject(const std::string& field, const std::string& name, const TriangleMesh& mesh,
                                 double mass) {
  const SolidProperties solid = ComputeSolidProperties(mesh);
  if (!(solid.volume > 0)) ThrowInvalidArgument(field + ": the completed mesh encloses no volume");
  auto local = std::make_shared<TriangleMesh>(mesh);
  for (auto& v : local->vertices) v -= solid.centroid.cast<float>();
  AddObjectEdit edit;
  edit.name = name;
  edit.pose.position = solid.centroid;
  edit.shape.emplace();
  edit.shape->kind = Geometry::Kind::kMesh;
  edit.shape->mesh = std::move(local);
  const double density = mass / solid.volume;
  edit.inertial.emplace();
  edit.inertial->mass = mass;
  edit.inertial->inertia = density * (solid.second_moment.trace() * Mat3::Identity() - solid.second_moment);
  return edit;
}

void Apply(Scene* scene, const Edit& edit, const Limits& limits) {
  std::visit(
      [&](const auto& e) {
        using T = std::decay_t<decltype(e)>;
        if constexpr (std::is_same_v<T, AddObjectEdit>) AddObject(scene, e, limits);
        if constexpr (std::is_same_v<T, AddRobotEdit>) AddRobot(scene, e, limits);
        if constexpr (std::is_same_v<T, RemoveBodyEdit>) RemoveBody(scene, e);
        if constexpr (std::is_same_v<T, SetSimulationParamsEdit>) SetSimulationParams(scene, e);
      },
      edit);
}

}  // namespace graspsim::edits
