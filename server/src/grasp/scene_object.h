// The object of a grasp request taken from a scene: one body's collision geometry as a mesh in its body frame
// (primitives tessellated), and every other body's geometries as obstacle boxes in that frame.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "core/mesh.h"
#include "grasp/grasp_object.h"
#include "world/model.h"
#include "world/state.h"

namespace graspsim::grasp {

struct SceneObject {
  std::shared_ptr<const TriangleMesh> mesh;  // body frame
  std::vector<ObstacleBox> obstacles;        // body frame
  Pose pose;                                 // the body's world pose
};

// Throws Error(kNotFound) naming `field` when the body does not exist, kInvalidArgument when it has no
// collision geometry. Bodies of the robots in `skip_robots` are no obstacles (the arm that will carry the hand).
SceneObject ObjectFromScene(const SceneModel& model, const SceneState& state, const std::string& field,
                            const std::string& body_id, const std::vector<std::string>& skip_robots = {});

}  // namespace graspsim::grasp
