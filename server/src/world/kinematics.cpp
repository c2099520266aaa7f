#include "world/state.h"

#include <algorithm>

namespace graspsim {

Vec3 FindBristle(const SceneState& state, const ContactKey& key) {
  const auto found = std::lower_bound(state.bristles.begin(), state.bristles.end(), key,
                                      [](const auto& entry, const ContactKey& k) { return entry.first < k; });
  return found != state.bristles.end() && found->first == key ? found->second : Vec3::Zero();
}

Pose JointMotion(const JointSpec& joint, double q) {
  switch (joint.type) {
    case JointType::kRevolute:
    case JointType::kContinuous:
      return {Vec3::Zero(), Quat(Eigen::AngleAxisd(q, joint.axis))};
    case JointType::kPrismatic:
      return {joint.axis * q, Quat::Identity()};
    case JointType::kFixed:
      break;
  }
  return {};
}

void UpdateRobotLinkPoses(const SceneModel& model, const RobotSpec& robot, SceneState* state) {
  // joint_ids are in topological order, so every parent is placed before its child.
  for (const std::string& joint_id : robot.joint_ids) {
    const size_t j = model.joint_index.at(joint_id);
    const JointSpec& joint = model.joints[j];
    const Pose& parent = state->body_poses[model.body_index.at(joint.parent_body)];
    state->body_poses[model.body_index.at(joint.child_body)] =
        parent * joint.origin * JointMotion(joint, state->joint_positions[j]);
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
}

}  // namespace graspsim
