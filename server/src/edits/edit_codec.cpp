#include "edits/edit_codec.h"

#include <cstring>
#include <string_view>

#include <nlohmann/json.hpp>

#include "core/error.h"

namespace graspsim::edits {
namespace {

using nlohmann::json;

constexpr std::string_view kMagic = "GSEDIT";

// Enums by name, so that a reordered enum cannot change what a stored record means.
template <typename Enum, size_t N>
struct Names {
  std::pair<Enum, const char*> entries[N];
  const char* Of(Enum value) const {
    for (const auto& [e, name] : entries) {
      if (e == value) return name;
    }
    throw Error(ErrorCode::kInternal, "edit record: an enum value without a name");
  }
  Enum From(const std::string& field, const std::string& name) const {
    for (const auto& [e, n] : entries) {
      if (name == n) return e;
    }
    throw Error(ErrorCode::kInternal, "edit record: " + field + " '" + name + "' is not known");
  }
};

constexpr Names<Geometry::Kind, 4> kShapeKinds{{{Geometry::Kind::kBox, "box"},
                                               {Geometry::Kind::kSphere, "sphere"},
                                               {Geometry::Kind::kCylinder, "cylinder"},
                                               {Geometry::Kind::kMesh, "mesh"}}};
constexpr Names<InertiaSource, 3> kInertiaSources{{{InertiaSource::kAuto, "auto"},
                                                   {InertiaSource::kFromFile, "from_file"},
                                                   {InertiaSource::kFromGeometry, "from_geometry"}}};
constexpr Names<RobotFormat, 4> kRobotFormats{{{RobotFormat::kUrdf, "urdf"},
                                               {RobotFormat::kMjcf, "mjcf"},
                                               {RobotFormat::kSdf, "sdf"},
                                               {RobotFormat::kBuiltin, "builtin"}}};
constexpr Names<Integrator, 4> kIntegrators{{{Integrator::kSemiImplicitEuler, "semi_implicit_euler"},
                                             {Integrator::kLinearlyImplicitEuler, "linearly_implicit_euler"},
                                             {Integrator::kVelocityVerlet, "velocity_verlet"},
                                             {Integrator::kRungeKutta4, "runge_kutta_4"}}};
constexpr Names<PhysicsEngineKind, 3> kEngines{{{PhysicsEngineKind::kGraspsim, "graspsim"},
                                                {PhysicsEngineKind::kMujoco, "mujoco"},
                                                {PhysicsEngineKind::kBullet, "bullet"}}};

json Bytes(const void* data, size_t size) {
  const auto* begin = static_cast<const uint8_t*>(data);
  return json::binary(std::vector<uint8_t>(begin, begin + size));
}

const std::vector<uint8_t>& BytesOf(const json& j, const std::string& field) {
  if (!j.is_binary()) throw Error(ErrorCode::kInternal, "edit record: " + field + " is not a byte string");
  return j.get_binary();
}

json Encode(const Vec3& v) { return {v.x(), v.y(), v.z()}; }
Vec3 DecodeVec3(const json& j) { return Vec3(j.at(0).get<double>(), j.at(1).get<double>(), j.at(2).get<double>()); }

json Encode(const Pose& pose) {
  const Quat& q = pose.orientation;
  return {{"position", Encode(pose.position)}, {"orientation", {q.w(), q.x(), q.y(), q.z()}}};
}
Pose DecodePose(const json& j) {
  Pose pose;
  pose.position = DecodeVec3(j.at("position"));
  const json& q = j.at("orientation");
  pose.orientation = Quat(q.at(0).get<double>(), q.at(1).get<double>(), q.at(2).get<double>(), q.at(3).get<double>());
  return pose;
}

json Encode(const TriangleMesh& mesh) {
  return {{"vertices", Bytes(mesh.vertices.data(), mesh.vertices.size() * sizeof(mesh.vertices[0]))},
          {"triangles", Bytes(mesh.triangles.data(), mesh.triangles.size() * sizeof(mesh.triangles[0]))}};
}
template <typename T>
std::vector<T> Unpack(const json& j, const std::string& field) {
  const std::vector<uint8_t>& bytes = BytesOf(j, field);
  if (bytes.size() % sizeof(T) != 0) {
    throw Error(ErrorCode::kInternal, "edit record: " + field + " holds " + std::to_string(bytes.size()) +
                                          " bytes, not a multiple of " + std::to_string(sizeof(T)));
  }
  std::vector<T> out(bytes.size() / sizeof(T));
  // Eigen vectors are plain floats (standard layout), whatever their copy-assignment says.
  if (!bytes.empty()) std::memcpy(static_cast<void*>(out.data()), bytes.data(), bytes.size());
  return out;
}
TriangleMesh DecodeMesh(const json& j) {
  TriangleMesh mesh;
  mesh.vertices = Unpack<Eigen::Vector3f>(j.at("vertices"), "shape.mesh.vertices");
  mesh.triangles = Unpack<std::array<uint32_t, 3>>(j.at("triangles"), "shape.mesh.triangles");
  return mesh;
}

json Encode(const ImportOptions& o) {
  return {{"inertia", kInertiaSources.Of(o.inertia)}, {"density", o.density}, {"strict", o.strict},
          {"model_name", o.model_name}};
}
ImportOptions DecodeImportOptions(const json& j) {
  ImportOptions o;
  o.inertia = kInertiaSources.From("import_options.inertia", j.at("inertia").get<std::string>());
  o.density = j.at("density").get<double>();
  o.strict = j.at("strict").get<bool>();
  o.model_name = j.at("model_name").get<std::string>();
  return o;
}

json Encode(const ShapeSpec& s) {
  json j = {{"kind", kShapeKinds.Of(s.kind)}, {"box_size", Encode(s.box_size)}, {"radius", s.radius},
            {"length", s.length}, {"mesh_file", s.mesh_file}, {"scale", Encode(s.scale)},
            {"origin", Encode(s.origin)}};
  if (s.mesh) j["mesh"] = Encode(*s.mesh);
  return j;
}
ShapeSpec DecodeShape(const json& j) {
  ShapeSpec s;
  s.kind = kShapeKinds.From("shape.kind", j.at("kind").get<std::string>());
  s.box_size = DecodeVec3(j.at("box_size"));
  s.radius = j.at("radius").get<double>();
  s.length = j.at("length").get<double>();
  s.mesh_file = j.at("mesh_file").get<std::string>();
  s.scale = DecodeVec3(j.at("scale"));
  s.origin = DecodePose(j.at("origin"));
  if (j.contains("mesh")) s.mesh = std::make_shared<const TriangleMesh>(DecodeMesh(j.at("mesh")));
  return s;
}

json Encode(const Inertial& i) {
  const Mat3& m = i.inertia;
  return {{"mass", i.mass}, {"center_of_mass", Encode(i.center_of_mass)},
          {"inertia", {m(0, 0), m(0, 1), m(0, 2), m(1, 0), m(1, 1), m(1, 2), m(2, 0), m(2, 1), m(2, 2)}}};
}
Inertial DecodeInertial(const json& j) {
  Inertial i;
  i.mass = j.at("mass").get<double>();
  i.center_of_mass = DecodeVec3(j.at("center_of_mass"));
  const json& m = j.at("inertia");
  for (int k = 0; k < 9; ++k) i.inertia(k / 3, k % 3) = m.at(k).get<double>();
  return i;
}

// The material's six contact parameters, by the names the API uses.
template <typename Spec>
auto ContactFields(Spec& m) {
  return std::array{std::pair{"contact_stiffness", &m.contact_stiffness}, std::pair{"contact_damping", &m.contact_damping},
                    std::pair{"bristle_stiffness", &m.bristle_stiffness}, std::pair{"bristle_damping", &m.bristle_damping},
                    std::pair{"viscous_friction", &m.viscous_friction},
                    std::pair{"stribeck_velocity", &m.stribeck_velocity}};
}

json Encode(const MaterialSpec& m) {
  json j = json::object();
  if (m.static_friction) j["static_friction"] = *m.static_friction;
  if (m.dynamic_friction) j["dynamic_friction"] = *m.dynamic_friction;
  for (const auto& [name, value] : ContactFields(m)) j[name] = *value;
  return j;
}
MaterialSpec DecodeMaterial(const json& j) {
  MaterialSpec m;
  if (j.contains("static_friction")) m.static_friction = j.at("static_friction").get<double>();
  if (j.contains("dynamic_friction")) m.dynamic_friction = j.at("dynamic_friction").get<double>();
  for (const auto& [name, value] : ContactFields(m)) *value = j.at(name).get<double>();
  return m;
}

json Encode(const SimulationParams& p) {
  const ContactParams& c = p.contact;
  return {{"time_step", p.time_step}, {"substeps", p.substeps}, {"integrator", kIntegrators.Of(p.integrator)},
          {"engine", kEngines.Of(p.engine)}, {"gravity", Encode(p.gravity)},
          {"contact", {{"stiffness", c.stiffness}, {"damping", c.damping}, {"static_friction", c.static_friction},
                       {"dynamic_friction", c.dynamic_friction}, {"bristle_stiffness", c.bristle_stiffness},
                       {"bristle_damping", c.bristle_damping}, {"viscous_friction", c.viscous_friction},
                       {"stribeck_velocity", c.stribeck_velocity}}},
          {"sample_spacing", p.sample_spacing}, {"sleep_speed", p.sleep_speed}, {"sleep_time", p.sleep_time},
          {"divergence_speed", p.divergence_speed}};
}
SimulationParams DecodeSimulationParams(const json& j) {
  SimulationParams p;
  p.time_step = j.at("time_step").get<double>();
  p.substeps = j.at("substeps").get<int>();
  p.integrator = kIntegrators.From("params.integrator", j.at("integrator").get<std::string>());
  p.engine = kEngines.From("params.engine", j.at("engine").get<std::string>());
  p.gravity = DecodeVec3(j.at("gravity"));
  const json& c = j.at("contact");
  p.contact.stiffness = c.at("stiffness").get<double>();
  p.contact.damping = c.at("damping").get<double>();
  p.contact.static_friction = c.at("static_friction").get<double>();
  p.contact.dynamic_friction = c.at("dynamic_friction").get<double>();
  p.contact.bristle_stiffness = c.at("bristle_stiffness").get<double>();
  p.contact.bristle_damping = c.at("bristle_damping").get<double>();
  p.contact.viscous_friction = c.at("viscous_friction").get<double>();
  p.contact.stribeck_velocity = c.at("stribeck_velocity").get<double>();
  p.sample_spacing = j.at("sample_spacing").get<double>();
  p.sleep_speed = j.at("sleep_speed").get<double>();
  p.sleep_time = j.at("sleep_time").get<double>();
  p.divergence_speed = j.at("divergence_speed").get<double>();
  return p;
}

json Fields(const AddObjectEdit& e) {
  json j = {{"name", e.name}, {"pose", Encode(e.pose)}, {"is_static", e.is_static}, {"builtin", e.builtin},
            {"import_options", Encode(e.import_options)}};
  if (e.shape) j["shape"] = Encode(*e.shape);
  if (e.inertial) j["inertial"] = Encode(*e.inertial);
  if (e.material) j["material"] = Encode(*e.material);
  return j;
}
json Fields(const AddRobotEdit& e) {
  json files = json::object();
  for (const auto& [path, bytes] : e.files) files[path] = Bytes(bytes->data(), bytes->size());
  return {{"name", e.name}, {"base_pose", Encode(e.base_pose)}, {"format", kRobotFormats.Of(e.format)},
          {"source", e.source}, {"files", files}, {"import_options", Encode(e.import_options)}};
}
json Fields(const RemoveBodyEdit& e) { return {{"id", e.id}}; }
json Fields(const SetSimulationParamsEdit& e) { return {{"params", Encode(e.params)}}; }

Edit DecodeFields(const std::string& kind, const json& j) {
  if (kind == "AddObject") {
    AddObjectEdit e;
    e.name = j.at("name").get<std::string>();
    e.pose = DecodePose(j.at("pose"));
    e.is_static = j.at("is_static").get<bool>();
    e.builtin = j.at("builtin").get<std::string>();
    e.import_options = DecodeImportOptions(j.at("import_options"));
    if (j.contains("shape")) e.shape = DecodeShape(j.at("shape"));
    if (j.contains("inertial")) e.inertial = DecodeInertial(j.at("inertial"));
    if (j.contains("material")) e.material = DecodeMaterial(j.at("material"));
    return e;
  }
  if (kind == "AddRobot") {
    AddRobotEdit e;
    e.name = j.at("name").get<std::string>();
    e.base_pose = DecodePose(j.at("base_pose"));
    e.format = kRobotFormats.From("format", j.at("format").get<std::string>());
    e.source = j.at("source").get<std::string>();
    for (const auto& [path, bytes] : j.at("files").items()) {
      const std::vector<uint8_t>& data = BytesOf(bytes, "files['" + path + "']");
      e.files[path] = std::make_shared<const std::string>(data.begin(), data.end());
    }
    e.import_options = DecodeImportOptions(j.at("import_options"));
    return e;
  }
  if (kind == "RemoveBody") return RemoveBodyEdit{j.at("id").get<std::string>()};
  if (kind == "SetSimulationParams") return SetSimulationParamsEdit{DecodeSimulationParams(j.at("params"))};
  throw Error(ErrorCode::kInternal, "edit record: unknown kind '" + kind + "'");
}

}  // namespace

const char* KindOf(const Edit& edit) {
  static constexpr const char* kKinds[] = {"AddObject", "AddRobot", "RemoveBody", "SetSimulationParams"};
  return kKinds[edit.index()];
}

SceneOp EncodeEdit(const Edit& edit) {
  SceneOp op;
  op.kind = KindOf(edit);
  const json fields = std::visit([](const auto& e) { return Fields(e); }, edit);
  const std::vector<uint8_t> cbor = json::to_cbor(fields);
  op.payload.reserve(kMagic.size() + 1 + cbor.size());
  op.payload.append(kMagic);
  op.payload.push_back(static_cast<char>(kEditFormatVersion));
  op.payload.append(cbor.begin(), cbor.end());
  return op;
}

bool IsEditRecord(const SceneOp& op) { return op.payload.size() > kMagic.size() && op.payload.starts_with(kMagic); }

Edit DecodeEdit(const SceneOp& op) {
  if (!IsEditRecord(op)) throw Error(ErrorCode::kInternal, "edit record: no GSEDIT header");
  const int version = static_cast<unsigned char>(op.payload[kMagic.size()]);
  if (version != kEditFormatVersion) {
    throw Error(ErrorCode::kInternal, "edit record: format version " + std::to_string(version) +
                                          " is not the one this server reads (" +
                                          std::to_string(kEditFormatVersion) + ")");
  }
  try {
    const auto* begin = reinterpret_cast<const uint8_t*>(op.payload.data()) + kMagic.size() + 1;
    const json fields = json::from_cbor(begin, reinterpret_cast<const uint8_t*>(op.payload.data()) + op.payload.size());
    return DecodeFields(op.kind, fields);
  } catch (const json::exception& error) {
    throw Error(ErrorCode::kInternal, "edit record " + op.kind + ": " + error.what());
  }
}

}  // namespace graspsim::edits
