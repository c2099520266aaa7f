// Translation between protobuf messages and engine types. Every FromProto validates at the boundary and throws
// Error naming the request field (e.g. "poses[2].pose.orientation") and the bad value.
#pragma once

#include <string>

#include "graspsim/v1/common.pb.h"
#include "graspsim/v1/scene.pb.h"
#include "import/robot_import.h"
#include "world/loaders.h"
#include "world/scene.h"

namespace graspsim::rpc {

Vec3 FromProto(const v1::Vec3& v);
// An absent orientation is the identity; a present one must be within 1e-3 of unit norm and is normalised.
Pose PoseFromProto(const std::string& field, const v1::Pose& pose);
Inertial InertialFromProto(const std::string& field, const v1::Inertial& inertial);
// The arrays unpacked, their sizes and the triangle limit checked (before allocating); MeshFromProto checks the
// mesh too (ValidateMesh). The edit API checks the meshes of its records itself, so AddObject only unpacks.
TriangleMesh UnpackMesh(const std::string& field, const v1::MeshData& mesh, const Limits& limits);
TriangleMesh MeshFromProto(const std::string& field, const v1::MeshData& mesh, const Limits& limits);

// Robot and object import options (docs/import.md); density 0 = 1000 kg/m^3.
ImportOptions ImportOptionsFromProto(const std::string& field, const v1::ImportOptions& options);
void ToProto(const ImportWarning& warning, v1::ImportWarning* out);

void ToProto(const Vec3& v, v1::Vec3* out);
void ToProto(const Pose& pose, v1::Pose* out);
void ToProto(const TriangleMesh& mesh, v1::MeshData* out);
void ToProto(const BodySpec& body, const Pose& pose, bool include_geometry, v1::Body* out);
void ToProto(const JointSpec& joint, double position, v1::Joint* out);
void ToProto(const TactileArraySpec& pad, v1::TactileArray* out);
void ToProto(const RobotSpec& robot, v1::Robot* out);
void ToProto(const SceneView& view, bool include_geometry, v1::Scene* out);
void SummaryToProto(const SceneView& view, v1::SceneSummary* out);

// Simulation parameters and actuators (convert_simulation.cpp). Fields left at 0 keep `defaults`.
SimulationParams SimulationParamsFromProto(const std::string& field, const v1::SimulationParams& params,
                                           const SimulationParams& defaults);
void ToProto(const SimulationParams& params, v1::SimulationParams* out);
DcMotorParams DcMotorFromProto(const std::string& field, const v1::DcMotor& motor);
ActuatorCommand ActuatorCommandFromProto(const std::string& field, const v1::ActuatorCommand& command);

}  // namespace graspsim::rpc
