// The edits of a scene's model as typed records: what a caller asked for, before anything is loaded or checked
// against the scene. The gRPC layer decodes its requests into these, perception adds completed meshes with them,
// and the journal stores them (edit_codec.h), so a restart, an archive or a recording's replay rebuilds a scene
// through the same code as the original edit (scene_edits.h).
#pragma once

#include <map>
#include <memory>
#include <optional>
#include <string>
#include <variant>

#include "core/math.h"
#include "core/mesh.h"
#include "import/robot_import.h"
#include "world/model.h"
#include "world/simulation_params.h"

namespace graspsim::edits {

// One shape as given: sizes, an inline mesh, or the path of a file uploaded to the scene. Sizes and the scale are
// checked, and a file is loaded, when the edit is applied (ShapeGeometry in scene_edits.h).
struct ShapeSpec {
  Geometry::Kind kind = Geometry::Kind::kBox;
  Vec3 box_size = Vec3::Zero();  // full edge lengths, m
  double radius = 0;             // sphere and cylinder, m
  double length = 0;             // cylinder along z, m
  std::shared_ptr<const TriangleMesh> mesh;  // kMesh given inline, unscaled (null for a file)
  std::string mesh_file;         // kMesh from an uploaded file
  Vec3 scale = Vec3::Ones();     // per-axis, meshes only
  Pose origin;                   // geometry frame in the body frame
};

// Surface settings laid over the body's own material (a built-in model's, else Material's defaults). Friction
// coefficients not given keep the body's; contact parameters at 0 take the scene's defaults.
struct MaterialSpec {
  std::optional<double> static_friction, dynamic_friction;
  double contact_stiffness = 0, contact_damping = 0, bristle_stiffness = 0, bristle_damping = 0,
         viscous_friction = 0, stribeck_velocity = 0;
};

// A rigid object: one shape or a built-in object model.
struct AddObjectEdit {
  std::string name;
  Pose pose;
  bool is_static = false;
  std::optional<ShapeSpec> shape;  // exactly one of shape and builtin
  std::string builtin;
  std::optional<Inertial> inertial;     // absent: the built-in's, or the solid shape's at import_options.density
  std::optional<MaterialSpec> material;
  ImportOptions import_options;
};

enum class RobotFormat { kUrdf, kMjcf, kSdf, kBuiltin };

// A robot from its description file (the text) or a built-in robot (the name), with the files the text names.
struct AddRobotEdit {
  std::string name;
  Pose base_pose;
  RobotFormat format = RobotFormat::kUrdf;
  std::string source;  // the URDF/MJCF/SDF text, or the built-in's name
  std::map<std::string, std::shared_ptr<const std::string>> files;  // path → bytes, beside the scene's uploads
  ImportOptions import_options;
};

// A body (an object, or a robot with all its links).
struct RemoveBodyEdit {
  std::string id;
};

struct SetSimulationParamsEdit {
  SimulationParams params;
};

using Edit = std::variant<AddObjectEdit, AddRobotEdit, RemoveBodyEdit, SetSimulationParamsEdit>;

// The journal's name of an edit ("AddObject", "AddRobot", "RemoveBody", "SetSimulationParams").
const char* KindOf(const Edit& edit);

}  // namespace graspsim::edits
