// The mutable part of a scene (MuJoCo's mjData), indexed like the SceneModel it belongs to.
#pragma once

#include <vector>

#include "core/math.h"
#include "world/model.h"

namespace graspsim {

struct SceneState {
  double time = 0;                      // simulation time, s
  std::vector<Pose> body_poses;         // world pose of every body (links placed by forward kinematics)
  std::vector<double> joint_positions;  // rad or m, per joint (0 for fixed joints)
};

// Places every link of `robot` from its base pose and joint positions (parents before children).
void UpdateRobotLinkPoses(const SceneModel& model, const RobotSpec& robot, SceneState* state);

// Transform of a joint's child frame relative to its joint frame at position q (rad or m).
Pose JointMotion(const JointSpec& joint, double q);

}  // namespace graspsim
