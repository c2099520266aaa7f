#include "rpc/convert.h"

#include "core/error.h"
#include "core/format.h"
#include "core/validate.h"
#include "rpc/packed_arrays.h"

namespace graspsim::rpc {

Vec3 FromProto(const v1::Vec3& v) { return {v.x(), v.y(), v.z()}; }

Pose PoseFromProto(const std::string& field, const v1::Pose& pose) {
  Pose out;
  out.position = FromProto(pose.position());
  if (pose.has_orientation()) {
    const auto& q = pose.orientation();
    out.orientation = Quat(q.w(), q.x(), q.y(), q.z());
  }
  CheckPose(field, &out);
  return out;
}

Inertial InertialFromProto(const std::string& field, const v1::Inertial& inertial) {
  Inertial out;
  CheckPositive(field + ".mass", inertial.mass());
  out.mass = inertial.mass();
  out.center_of_mass = FromProto(inertial.center_of_mass());
  CheckFinite(field + ".center_of_mass", out.center_of_mass);
  out.inertia << inertial.ixx(), inertial.ixy(), inertial.ixz(),  //
      inertial.ixy(), inertial.iyy(), inertial.iyz(),             //
      inertial.ixz(), inertial.iyz(), inertial.izz();
  CheckInertia(field, out.inertia);
  return out;
}

ImportOptions ImportOptionsFromProto(const std::string& field, const v1::ImportOptions& options) {
  ImportOptions out;
  switch (options.inertia()) {
    case v1::INERTIA_SOURCE_AUTO: out.inertia = InertiaSource::kAuto; break;
    case v1::INERTIA_SOURCE_FROM_FILE: out.inertia = InertiaSource::kFromFile; break;
    case v1::INERTIA_SOURCE_FROM_GEOMETRY: out.inertia = InertiaSource::kFromGeometry; break;
    default: ThrowInvalidArgument(field + ".inertia: " + std::to_string(options.inertia()) + " is not an InertiaSource");
  }
  CheckNonNegative(field + ".density", options.density());
  if (options.density() > 0) out.density = options.density();
  out.strict = options.strict();
  out.model_name = options.model_name();
  return out;
}

void ToProto(const ImportWarning& warning, v1::ImportWarning* out) {
  out->set_element(warning.element);
  out->set_value(warning.value);
  out->set_action(warning.action);
}

TriangleMesh UnpackMesh(const std::string& field, const v1::MeshData& mesh, const Limits& limits) {
  constexpr char kVertex[] = "three float32 per vertex", kTriangle[] = "three uint32 per triangle";
  PackedCount(field + ".vertices", mesh.vertices().size(), 12, kVertex);
  const size_t triangles = PackedCount(field + ".triangles", mesh.triangles().size(), 12, kTriangle);
  // Checked before allocating, so an oversized mesh costs nothing.
  if (triangles > limits.max_triangles_per_mesh) {
    ThrowResourceExhausted(field + ": mesh has " + std::to_string(triangles) + " triangles, above the limit of " +
                           std::to_string(limits.max_triangles_per_mesh));
  }
  TriangleMesh out;
  out.vertices = Unpack<Eigen::Vector3f>(field + ".vertices", mesh.vertices(), kVertex);
  out.triangles = Unpack<std::array<uint32_t, 3>>(field + ".triangles", mesh.triangles(), kTriangle);
  return out;
}

TriangleMesh MeshFromProto(const std::string& field, const v1::MeshData& mesh, const Limits& limits) {
  TriangleMesh out = UnpackMesh(field, mesh, limits);
  ValidateMesh(out, field, limits.max_triangles_per_mesh);
  return out;
}

void ToProto(const Vec3& v, v1::Vec3* out) {
  out->set_x(v.x());
  out->set_y(v.y());
  out->set_z(v.z());
}

void ToProto(const Pose& pose, v1::Pose* out) {
  ToProto(pose.position, out->mutable_position());
  auto* q = out->mutable_orientation();
  q->set_w(pose.orientation.w());
  q->set_x(pose.orientation.x());
  q->set_y(pose.orientation.y());
  q->set_z(pose.orientation.z());
}

void ToProto(const TriangleMesh& mesh, v1::MeshData* out) {
  out->set_vertices(Pack(mesh.vertices));
  out->set_triangles(Pack(mesh.triangles));
}

namespace {

v1::BodyMotion MotionToProto(BodyMotion motion) {
  switch (motion) {
    case BodyMotion::kStatic: return v1::BODY_MOTION_STATIC;
    case BodyMotion::kFree: return v1::BODY_MOTION_FREE;
    case BodyMotion::kArticulated: return v1::BODY_MOTION_ARTICULATED;
  }
  return v1::BODY_MOTION_UNSPECIFIED;
}

v1::JointType JointTypeToProto(JointType type) {
  switch (type) {
    case JointType::kRevolute: return v1::JOINT_TYPE_REVOLUTE;
    case JointType::kContinuous: return v1::JOINT_TYPE_CONTINUOUS;
    case JointType::kPrismatic: return v1::JOINT_TYPE_PRISMATIC;
    case JointType::kFixed: return v1::JOINT_TYPE_FIXED;
  }
  return v1::JOINT_TYPE_UNSPECIFIED;
}

void GeometryToProto(const Geometry& geometry, bool include_geometry, v1::Geometry* out) {
  ToProto(geometry.origin, out->mutable_origin());
  switch (geometry.kind) {
    case Geometry::Kind::kBox: ToProto(geometry.box_size, out->mutable_box()->mutable_size()); break;
    case Geometry::Kind::kSphere: out->mutable_sphere()->set_radius(geometry.radius); break;
    case Geometry::Kind::kCylinder:
      out->mutable_cylinder()->set_radius(geometry.radius);
      out->mutable_cylinder()->set_length(geometry.length);
      break;
    case Geometry::Kind::kMesh:
      // Meshes are big: sent only on request, otherwise named by their file when they came from one.
      if (include_geometry) {
        ToProto(*geometry.mesh, out->mutable_mesh());
      } else if (!geometry.mesh_file.empty()) {
        out->set_mesh_file(geometry.mesh_file);
      }
      break;
  }
}

}  // namespace

void ToProto(const BodySpec& body, const Pose& pose, bool include_geometry, v1::Body* out) {
  out->set_id(body.id);
  out->set_robot_id(body.robot_id);
  out->set_motion(MotionToProto(body.motion));
  uint32_t triangles = 0;
  for (const Geometry& geometry : body.collision) {
    GeometryToProto(geometry, include_geometry, out->add_collision());
    if (geometry.mesh) triangles += geometry.mesh->TriangleCount();
  }
  out->set_triangle_count(triangles);
  auto* inertial = out->mutable_inertial();
  inertial->set_mass(body.inertial.mass);
  ToProto(body.inertial.center_of_mass, inertial->mutable_center_of_mass());
  const Mat3& I = body.inertial.inertia;
  inertial->set_ixx(I(0, 0));
  inertial->set_iyy(I(1, 1));
  inertial->set_izz(I(2, 2));
  inertial->set_ixy(I(0, 1));
  inertial->set_ixz(I(0, 2));
  inertial->set_iyz(I(1, 2));
  auto* material = out->mutable_material();
  material->set_static_friction(body.material.static_friction);
  material->set_dynamic_friction(body.material.dynamic_friction);
  material->set_contact_stiffness(body.material.contact_stiffness);
  material->set_contact_damping(body.material.contact_damping);
  material->set_bristle_stiffness(body.material.bristle_stiffness);
  material->set_bristle_damping(body.material.bristle_damping);
  material->set_viscous_friction(body.material.viscous_friction);
  material->set_stribeck_velocity(body.material.stribeck_velocity);
  ToProto(pose, out->mutable_pose());
}

void ToProto(const JointSpec& joint, double position, v1::Joint* out) {
  out->set_id(joint.id);
  out->set_robot_id(joint.robot_id);
  out->set_type(JointTypeToProto(joint.type));
  out->set_parent_body(joint.parent_body);
  out->set_child_body(joint.child_body);
  ToProto(joint.origin, out->mutable_origin());
  ToProto(joint.axis, out->mutable_axis());
  out->set_lower(joint.lower);
  out->set_upper(joint.upper);
  out->set_velocity_limit(joint.velocity_limit);
  out->set_effort_limit(joint.effort_limit);
  out->set_position(position);
  if (joint.mimic) {
    out->mutable_mimic()->set_joint_id(joint.mimic->joint_id);
    out->mutable_mimic()->set_multiplier(joint.mimic->multiplier);
    out->mutable_mimic()->set_offset(joint.mimic->offset);
  }
}

void ToProto(const TactileArraySpec& pad, v1::TactileArray* out) {
  out->set_id(pad.id);
  out->set_body_id(pad.body_id);
  ToProto(pad.origin, out->mutable_origin());
  out->set_rows(pad.rows);
  out->set_cols(pad.cols);
  out->set_pitch(pad.pitch);
  out->set_thickness(pad.thickness);
  out->set_subdivision(pad.subdivision);
  out->set_elements(pad.placement == PadElementPlacement::kFaceCentres ? "face_centres" : "vertices");
  out->set_bend_radius_x(pad.bend_radius_x);
  out->set_bend_radius_y(pad.bend_radius_y);
}

void ToProto(const RobotSpec& robot, v1::Robot* out) {
  out->set_id(robot.id);
  out->set_source(robot.source);
  out->set_base_body(robot.base_body);
  for (const auto& id : robot.body_ids) out->add_body_ids(id);
  for (const auto& id : robot.joint_ids) out->add_joint_ids(id);
  for (const auto& id : robot.tactile_array_ids) out->add_tactile_array_ids(id);
}

void SummaryToProto(const SceneView& view, v1::SceneSummary* out) {
  out->set_id(view.id);
  out->set_name(view.name);
  out->set_body_count(view.model->bodies.size());
  out->set_robot_count(view.model->robots.size());
  out->set_revision(view.revision);
  out->set_time(view.state.time);
}

void ToProto(const SceneView& view, bool include_geometry, v1::Scene* out) {
  const SceneModel& model = *view.model;
  SummaryToProto(view, out->mutable_summary());
  for (size_t i = 0; i < model.bodies.size(); ++i) {
    v1::Body* body = out->add_bodies();
    ToProto(model.bodies[i], view.state.body_poses[i], include_geometry, body);
    if (i < view.state.body_velocities.size()) {
      ToProto(view.state.body_velocities[i].linear, body->mutable_velocity()->mutable_linear());
      ToProto(view.state.body_velocities[i].angular, body->mutable_velocity()->mutable_angular());
      body->set_sleeping(view.state.sleeping[i]);
    }
  }
  for (size_t j = 0; j < model.joints.size(); ++j) {
    v1::Joint* joint = out->add_joints();
    ToProto(model.joints[j], view.state.joint_positions[j], joint);
    if (j < view.state.joint_velocities.size()) joint->set_velocity(view.state.joint_velocities[j]);
  }
  for (const auto& robot : model.robots) ToProto(robot, out->add_robots());
  for (const auto& pad : model.tactile_arrays) ToProto(pad, out->add_tactile_arrays());
  for (const auto& [path, file] : view.files) {
    auto* info = out->add_files();
    info->set_path(path);
    info->set_size(file.bytes->size());
    info->set_sha256(file.sha256);
  }
}

}  // namespace graspsim::rpc
