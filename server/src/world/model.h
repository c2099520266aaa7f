// The immutable part of a scene (MuJoCo's mjModel): bodies with geometry and mass, joints, robots, tactile
// arrays. A SceneModel is built once per change and shared read-only (shared_ptr<const SceneModel>); every
// accepted edit builds a new one, so a rejected edit leaves the old one untouched.
#pragma once

#include <array>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "core/math.h"
#include "core/mesh.h"
#include "world/simulation_params.h"

namespace graspsim {

struct Geometry {
  enum class Kind { kBox, kSphere, kCylinder, kMesh };
  Kind kind = Kind::kBox;
  Vec3 box_size = Vec3::Zero();   // full edge lengths, m
  double radius = 0;              // sphere and cylinder, m
  double length = 0;              // cylinder along z, m
  std::shared_ptr<const TriangleMesh> mesh;  // kMesh: already scaled, in the geometry frame
  std::string mesh_file;          // kMesh: the uploaded file it came from, if any
  Pose origin;                    // geometry frame in the body frame
};

struct Inertial {
  double mass = 0;                // kg
  Vec3 center_of_mass = Vec3::Zero();  // m, body frame
  Mat3 inertia = Mat3::Zero();    // kg m^2 about the centre of mass, body frame
};

// Surface properties of a body. Contact parameters left at 0 take the scene's defaults (SimulationParams).
struct Material {
  double static_friction = 0.6;
  double dynamic_friction = 0.4;
  double contact_stiffness = 0;   // k, N/m per contact point
  double contact_damping = 0;     // c, N s/m
  double bristle_stiffness = 0;   // LuGre σ0, N/m
  double bristle_damping = 0;     // LuGre σ1, N s/m
  double viscous_friction = 0;    // c_t, N s/m
  double stribeck_velocity = 0;   // v_s, m/s
};

enum class BodyMotion { kStatic, kFree, kArticulated };

struct BodySpec {
  std::string id;                 // "<object>" or "<robot>/<link>"
  std::string robot_id;           // empty for objects
  BodyMotion motion = BodyMotion::kFree;
  std::vector<Geometry> collision;
  Inertial inertial;
  Material material;
};

enum class JointType { kRevolute, kContinuous, kPrismatic, kFixed };

struct MimicSpec {
  std::string joint_id;           // the leader
  double multiplier = 1;
  double offset = 0;
};

struct JointSpec {
  std::string id;                 // "<robot>/<joint>"
  std::string robot_id;
  JointType type = JointType::kFixed;
  std::string parent_body;
  std::string child_body;
  Pose origin;                    // joint frame in the parent body frame at zero position
  Vec3 axis = Vec3::UnitX();      // unit, joint frame
  double lower = 0, upper = 0;    // rad or m (ignored for continuous)
  double velocity_limit = 0;      // rad/s or m/s; 0 = none given
  double effort_limit = 0;        // N m or N; 0 = none given
  std::optional<MimicSpec> mimic;
};

// A pad's frame: origin at the centre of the sensing area on the surface it is mounted on; cols along x, rows
// along y, the foam filling 0 <= z <= thickness and sensing along +z (toward what it touches).
// The sensing mesh is a grid of (rows · subdivision) × (cols · subdivision) equal cells over the sensing area,
// at z = 0 (the mounting surface), flat or bent into a curved fingertip (bend_radius). Sensing elements sit at
// the mesh's vertices (the cell centres) or at the centres of its triangles (a grid whose vertices are the cell
// corners, two triangles per cell); each casts a segment of length `thickness` along its normal and belongs to
// the texel of its cell (tactile/pad_elements.h). Contact parameters are per texel: a pad with several
// elements per texel shares them out (ElementsPerTexel), so the pad as a whole keeps them.
enum class PadElementPlacement { kVertices, kFaceCentres };

struct TactileArraySpec {
  std::string id;                 // "<robot>/<sensor>"
  std::string body_id;
  Pose origin;                    // pad frame in the body frame
  unsigned rows = 0, cols = 0;
  double pitch = 0;               // m
  double thickness = 0;           // m, the foam: maximum penetration
  unsigned subdivision = 1;       // mesh cells per texel edge
  PadElementPlacement placement = PadElementPlacement::kVertices;
  // A curved fingertip: the sensing area wrapped, arc length kept, around an axis parallel to the pad's y axis
  // at radius bend_radius_x (x bends) and around one parallel to x at bend_radius_y; 0 = flat in that direction.
  // The centre stands proud and the edges fall back, as on a rounded fingertip. At most a quarter turn each way:
  // radius ≥ width / π.
  double bend_radius_x = 0, bend_radius_y = 0;  // m
  // The foam's contact law (PAPERS.md part B's sensor definition: k 1e3, c 10, σ0 200, σ1 0.5, μs 0.9, μd 0.6).
  ContactParams contact{1e3, 10, 0.9, 0.6, 200, 0.5, 0, 1e-3};
  // DSA 9205 output: intensity = min(4095, intensity_per_newton · texel normal force). Assumption (no datasheet
  // value): 4095 at 3 N per 3.4 mm texel, about 260 kPa.
  double intensity_per_newton = 4095.0 / 3.0;
  unsigned max_intensity = 4095;  // 12 bit

  unsigned ElementsPerTexel() const {
    const unsigned s = subdivision > 0 ? subdivision : 1;
    return s * s * (placement == PadElementPlacement::kFaceCentres ? 2 : 1);
  }
  size_t ElementCount() const { return size_t{rows} * cols * ElementsPerTexel(); }
};

struct RobotSpec {
  std::string id;
  std::string source;             // "builtin:<name>" or "urdf"
  std::string base_body;
  std::vector<std::string> body_ids;   // in topological order: parents before children
  std::vector<std::string> joint_ids;  // in topological order
  std::vector<std::string> tactile_array_ids;
};

// What a URDF (or a built-in model) describes, before it is placed in a scene. Ids here are the plain URDF
// names; the scene prefixes them with "<robot>/".
struct RobotDescription {
  std::string name;               // the URDF's robot name
  std::string root_link;
  std::vector<BodySpec> links;    // topological order, root first; motion kArticulated
  std::vector<JointSpec> joints;  // topological order; parent_body/child_body are link names
  std::vector<TactileArraySpec> tactile_arrays;  // body_id is a link name
};

struct SceneModel {
  std::vector<BodySpec> bodies;
  std::vector<JointSpec> joints;
  std::vector<RobotSpec> robots;
  std::vector<TactileArraySpec> tactile_arrays;
  SimulationParams simulation;
  std::map<std::string, size_t> body_index, joint_index, robot_index, tactile_index;
  // Derived by Reindex, for per-step loops that must not look names up: per joint its parent and child body
  // indices; per robot its joints' indices in topological order.
  std::vector<std::array<size_t, 2>> joint_bodies;
  std::vector<std::vector<size_t>> robot_joints;

  // Rebuilds the id → index maps and the derived indices after the vectors changed.
  void Reindex();
};

}  // namespace graspsim
