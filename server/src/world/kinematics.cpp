#include "world/state.h"

namespace graspsim {

Pose JointMotion(JointType type, const Vec3& axis, double q) {
  switch (type) {
    case JointType::kRevolute:
    case JointType::kContinuous:
      return {Vec3::Zero(), Quat(Eigen::AngleAxisd(q, axis))};
    case JointType::kPrismatic:
      return {axis * q, Quat::Identity()};
    case JointType::kFixed:
      break;
  }
  return {};
}

Pose JointMotion(const JointSpec& joint, double q) { return JointMotion(joint.type, joint.axis, q); }

void UpdateRobotLinkPoses(const SceneModel& model, size_t robot, SceneState* state) {
  // Joints in topological order, so every parent is placed before its child; indices from Reindex (per step,
  // no name lookups).
  for (size_t j : model.robot_joints.at(robot)) {
    const JointSpec& joint = model.joints[j];
    const auto [parent, child] = model.joint_bodies.at(j);
    state->body_poses[child] = state->body_poses[parent] * joint.origin * JointMotion(joint, state->joint_positions[j]);
  }
}

void SceneModel::Reindex() {
  auto index = [](const auto& items, std::map<std::string, size_t>* out) {
    out->clear();
    for (size_t i = 0; i < items.size(); ++i) (*out)[items[i].id] = i;
  };
  index(bodies, &body_index);
  index(joints, &joint_index);
  index(robots, &robot_index);
  index(tactile_arrays, &tactile_index);
  // Bodies and joints are added together (Scene::AddRobot), so a name missing here is a bug: at() throws.
  joint_bodies.clear();
  for (const JointSpec& joint : joints) {
    joint_bodies.push_back({body_index.at(joint.parent_body), body_index.at(joint.child_body)});
  }
  robot_joints.assign(robots.size(), {});
  for (size_t r = 0; r < robots.size(); ++r) {
    for (const std::string& id : robots[r].joint_ids) robot_joints[r].push_back(joint_index.at(id));
  }
}

}  // namespace graspsim
