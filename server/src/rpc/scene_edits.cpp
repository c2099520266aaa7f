#include "rpc/scene_edits.h"

#include "core/error.h"
#include "core/validate.h"
#include "edits/scene_edits.h"
#include "rpc/convert.h"

namespace graspsim::rpc {
namespace {

// Sizes, scale and the mesh are checked by the edit API (edits::ShapeGeometry), where stored records are too.
edits::ShapeSpec ShapeFromProto(const std::string& field, const v1::Geometry& geometry, const Limits& limits) {
  edits::ShapeSpec shape;
  shape.origin = PoseFromProto(field + ".origin", geometry.origin());
  if (geometry.has_scale()) shape.scale = FromProto(geometry.scale());
  switch (geometry.shape_case()) {
    case v1::Geometry::kBox:
      shape.kind = Geometry::Kind::kBox;
      shape.box_size = FromProto(geometry.box().size());
      break;
    case v1::Geometry::kSphere:
      shape.kind = Geometry::Kind::kSphere;
      shape.radius = geometry.sphere().radius();
      break;
    case v1::Geometry::kCylinder:
      shape.kind = Geometry::Kind::kCylinder;
      shape.radius = geometry.cylinder().radius();
      shape.length = geometry.cylinder().length();
      break;
    case v1::Geometry::kMesh:
      shape.kind = Geometry::Kind::kMesh;
      shape.mesh = std::make_shared<const TriangleMesh>(UnpackMesh(field + ".mesh", geometry.mesh(), limits));
      break;
    case v1::Geometry::kMeshFile:
      shape.kind = Geometry::Kind::kMesh;
      shape.mesh_file = geometry.mesh_file();
      break;
    case v1::Geometry::SHAPE_NOT_SET:
      ThrowInvalidArgument(field + ": no shape given (box, sphere, cylinder, mesh or mesh_file)");
  }
  return shape;
}

// Checked by the edit API, after the shape: a bad size is named before the inertia computed from it.
Inertial InertialOf(const v1::Inertial& in) {
  Inertial out;
  out.mass = in.mass();
  out.center_of_mass = FromProto(in.center_of_mass());
  out.inertia << in.ixx(), in.ixy(), in.ixz(),  //
      in.ixy(), in.iyy(), in.iyz(),             //
      in.ixz(), in.iyz(), in.izz();
  return out;
}

edits::MaterialSpec MaterialFromProto(const v1::Material& m) {
  edits::MaterialSpec spec;
  if (m.has_static_friction()) spec.static_friction = m.static_friction();
  if (m.has_dynamic_friction()) spec.dynamic_friction = m.dynamic_friction();
  spec.contact_stiffness = m.contact_stiffness();
  spec.contact_damping = m.contact_damping();
  spec.bristle_stiffness = m.bristle_stiffness();
  spec.bristle_damping = m.bristle_damping();
  spec.viscous_friction = m.viscous_friction();
  spec.stribeck_velocity = m.stribeck_velocity();
  return spec;
}

edits::AddObjectEdit AddObjectEditFromProto(const v1::AddObjectRequest& request, const Limits& limits) {
  edits::AddObjectEdit edit;
  edit.name = request.name();
  edit.pose = PoseFromProto("pose", request.pose());
  edit.is_static = request.is_static();
  edit.import_options = ImportOptionsFromProto("import_options", request.import_options());
  switch (request.source_case()) {
    case v1::AddObjectRequest::kGeometry:
      edit.shape = ShapeFromProto("geometry", request.geometry(), limits);
      break;
    case v1::AddObjectRequest::kBuiltin:
      edit.builtin = request.builtin();
      break;
    case v1::AddObjectRequest::SOURCE_NOT_SET:
      break;  // refused by the edit API, naming `source`
  }
  if (request.has_inertial()) edit.inertial = InertialOf(request.inertial());
  if (request.has_material()) edit.material = MaterialFromProto(request.material());
  return edit;
}

edits::AddRobotEdit AddRobotEditFromProto(const v1::AddRobotRequest& request) {
  edits::AddRobotEdit edit;
  edit.name = request.name();
  edit.base_pose = PoseFromProto("base_pose", request.base_pose());
  edit.import_options = ImportOptionsFromProto("import_options", request.import_options());
  for (int i = 0; i < request.files_size(); ++i) {
    const auto& file = request.files(i);
    CheckRelativePath("files[" + std::to_string(i) + "].path", file.path());
    edit.files[file.path()] = std::make_shared<const std::string>(file.data());
  }
  switch (request.source_case()) {
    case v1::AddRobotRequest::kUrdf: edit.format = edits::RobotFormat::kUrdf; edit.source = request.urdf(); break;
    case v1::AddRobotRequest::kMjcf: edit.format = edits::RobotFormat::kMjcf; edit.source = request.mjcf(); break;
    case v1::AddRobotRequest::kSdf: edit.format = edits::RobotFormat::kSdf; edit.source = request.sdf(); break;
    case v1::AddRobotRequest::kBuiltin:
      edit.format = edits::RobotFormat::kBuiltin;
      edit.source = request.builtin();
      break;
    case v1::AddRobotRequest::SOURCE_NOT_SET:
      ThrowInvalidArgument("source: give urdf, mjcf, sdf or builtin");
  }
  return edit;
}

edits::SetSimulationParamsEdit SimulationParamsEditFromProto(const v1::SetSimulationParamsRequest& request) {
  return {SimulationParamsFromProto("params", request.params(), SimulationParams())};
}

template <typename Request>
Request Parse(const SceneOp& op) {
  Request request;
  if (!request.ParseFromString(op.payload)) throw Error(ErrorCode::kInternal, "the stored request does not parse");
  return request;
}

}  // namespace

void AddObjectFromRequest(Scene* scene, const v1::AddObjectRequest& request, const Limits& limits,
                          v1::Body* response) {
  const edits::AddedObject added = edits::AddObject(scene, AddObjectEditFromProto(request, limits), limits);
  ToProto(added.body, added.pose, false, response);
  for (const ImportWarning& warning : added.warnings) ToProto(warning, response->add_warnings());
}

void AddRobotFromRequest(Scene* scene, const v1::AddRobotRequest& request, const Limits& limits,
                         v1::AddRobotResponse* response) {
  const auto [added, warnings] = edits::AddRobot(scene, AddRobotEditFromProto(request), limits);
  // Report the placed links as the scene holds them now.
  const SceneView view = scene->View();
  ToProto(added.robot, response->mutable_robot());
  for (const auto& body : added.bodies) {
    ToProto(body, view.state.body_poses[view.model->body_index.at(body.id)], false, response->add_bodies());
  }
  for (const auto& joint : added.joints) {
    ToProto(joint, view.state.joint_positions[view.model->joint_index.at(joint.id)], response->add_joints());
  }
  for (const auto& pad : added.tactile_arrays) ToProto(pad, response->add_tactile_arrays());
  for (const ImportWarning& warning : warnings) ToProto(warning, response->add_warnings());
}

std::vector<std::string> RemoveBodyFromRequest(Scene* scene, const v1::RemoveBodyRequest& request) {
  return edits::RemoveBody(scene, {request.id()});
}

void SetSimulationParamsFromRequest(Scene* scene, const v1::SetSimulationParamsRequest& request,
                                    v1::SimulationParams* response) {
  const edits::SetSimulationParamsEdit edit = SimulationParamsEditFromProto(request);
  edits::SetSimulationParams(scene, edit);
  ToProto(edit.params, response);
}

edits::Edit LegacyEdit(const SceneOp& op, const Limits& limits) {
  if (op.kind == "AddObject") return AddObjectEditFromProto(Parse<v1::AddObjectRequest>(op), limits);
  if (op.kind == "AddRobot") return AddRobotEditFromProto(Parse<v1::AddRobotRequest>(op));
  if (op.kind == "RemoveBody") return edits::RemoveBodyEdit{Parse<v1::RemoveBodyRequest>(op).id()};
  if (op.kind == "SetSimulationParams") return SimulationParamsEditFromProto(Parse<v1::SetSimulationParamsRequest>(op));
  throw Error(ErrorCode::kInternal, "unknown edit kind '" + op.kind + "'");
}

edits::LegacyEditReader LegacyEditReaderFor(const Limits& limits) {
  return [limits](const SceneOp& op) { return LegacyEdit(op, limits); };
}

}  // namespace graspsim::rpc
