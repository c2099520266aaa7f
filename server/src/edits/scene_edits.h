// The typed edit API of a scene's model. Each call loads and checks what its record names (mesh files, robot
// descriptions, built-in models, the engine's capabilities), journals the record (edit_codec.h) and makes the edit
// visible, all or nothing; errors name the record's field as the API does ("geometry.mesh_file: ...").
// SceneService's handlers, perception's add-to-scene and the replay of stored edits (scene_restore.h) all come here.
#pragma once

#include <string>
#include <vector>

#include "core/limits.h"
#include "edits/edit_records.h"
#include "import/robot_import.h"
#include "world/scene.h"

namespace graspsim::edits {

struct AddedObject {
  BodySpec body;
  Pose pose;
  std::vector<ImportWarning> warnings;  // repairs made (mass properties from geometry)
};
AddedObject AddObject(Scene* scene, const AddObjectEdit& edit, const Limits& limits);

struct AddedRobotWithWarnings {
  AddedRobot added;
  std::vector<ImportWarning> warnings;
};
AddedRobotWithWarnings AddRobot(Scene* scene, const AddRobotEdit& edit, const Limits& limits);

// The ids of the bodies removed (a robot's every link).
std::vector<std::string> RemoveBody(Scene* scene, const RemoveBodyEdit& edit);

// Checks the parameters and that the engine they name simulates what the scene holds.
void SetSimulationParams(Scene* scene, const SetSimulationParamsEdit& edit);

// A closed mesh as a free object of uniform density and mass `mass`: the body frame at the solid's centroid, the
// mesh inline. Error(kInvalidArgument) naming `field` when the mesh encloses no volume. (CompleteShape's
// add-to-scene: the record is journaled like any other object, so a restart rebuilds it the same way.)
AddObjectEdit UniformSolidObject(const std::string& field, const std::string& name, const TriangleMesh& mesh,
                                 double mass);

// Any record, results dropped (replay).
void Apply(Scene* scene, const Edit& edit, const Limits& limits);

// A shape's geometry: sizes and scale checked, an inline mesh checked and scaled, a file loaded from `files` (the
// scene's uploads). Error(kInvalidArgument) naming `field`.
Geometry ShapeGeometry(const std::string& field, const ShapeSpec& shape, const FileLookup& files,
                       const Limits& limits);

}  // namespace graspsim::edits
