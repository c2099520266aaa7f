#include "motion/arm.h"

#include <algorithm>
#include <map>

#include "core/error.h"

namespace graspsim::motion {

Rigid JointRigid(JointType type, const Vec3& axis, double q) {
  switch (type) {
    case JointType::kRevolute:
    case JointType::kContinuous:
      return {Eigen::AngleAxisd(q, axis).toRotationMatrix(), Vec3::Zero()};
    case JointType::kPrismatic:
      return {Mat3::Identity(), axis * q};
    case JointType::kFixed:
      break;
  }
  return {};
}

ArmModel::ArmModel(const SceneModel& model, const SceneState& state, const std::string& robot_id,
                   const std::string& tip_body)
    : robot_id_(robot_id) {
  const auto robot_it = model.robot_index.find(robot_id);
  if (robot_it == model.robot_index.end()) ThrowNotFound("arm_id: robot '" + robot_id + "' is not in the scene");
  const RobotSpec& robot = model.robots[robot_it->second];
  base_ = Rigid::From(state.body_poses.at(model.body_index.at(robot.base_body)));

  // Links in the robot's topological order, each with the joint that carries it.
  std::map<size_t, int> link_of_body;
  std::map<size_t, size_t> joint_of_body;  // child body -> joint index
  for (const std::string& id : robot.joint_ids) {
    const size_t j = model.joint_index.at(id);
    joint_of_body[model.joint_bodies[j][1]] = j;
  }
  std::vector<size_t> link_joint;  // per link: joint index, or SIZE_MAX for the base
  for (const std::string& id : robot.body_ids) {
    const size_t body = model.body_index.at(id);
    ArmLink link;
    link.body = body;
    link.id = id;
    const auto joint = joint_of_body.find(body);
    if (joint != joint_of_body.end()) link.parent = link_of_body.at(model.joint_bodies[joint->second][0]);
    link_joint.push_back(joint == joint_of_body.end() ? SIZE_MAX : joint->second);
    link_of_body[body] = static_cast<int>(links_.size());
    links_.push_back(link);
  }

  // The tip: named, or the flange, or the end of the longest chain.
  std::string tip = tip_body;
  if (tip.empty()) {
    const std::string flange = robot_id + "/flange";
    if (std::find(robot.body_ids.begin(), robot.body_ids.end(), flange) != robot.body_ids.end()) {
      tip = flange;
    } else {
      std::vector<int> depth(links_.size(), 0);
      size_t deepest = 0;
      for (size_t i = 0; i < links_.size(); ++i) {
        if (links_[i].parent >= 0) depth[i] = depth[links_[i].parent] + 1;
        if (depth[i] > depth[deepest]) deepest = i;
      }
      tip = model.bodies[links_[deepest].body].id;
    }
  }
  const auto tip_it = model.body_index.find(tip);
  if (tip_it == model.body_index.end() || !link_of_body.count(tip_it->second)) {
    ThrowNotFound("tip_body: '" + tip + "' is not a body of robot '" + robot_id + "'");
  }
  tip_body_id_ = tip;
  tip_link_ = link_of_body.at(tip_it->second);

  // The path base -> tip; its movable, non-mimic joints are the dofs.
  std::vector<int> path;
  for (int l = tip_link_; l >= 0; l = links_[l].parent) path.push_back(l);
  std::reverse(path.begin(), path.end());
  std::vector<bool> is_dof_link(links_.size(), false);
  for (int l : path) {
    const size_t j = link_joint[l];
    if (j == SIZE_MAX) continue;
    const JointSpec& joint = model.joints[j];
    if (joint.type != JointType::kFixed && !joint.mimic) is_dof_link[l] = true;
  }
  for (size_t l = 0; l < links_.size(); ++l) {
    const size_t j = link_joint[l];
    if (j == SIZE_MAX) continue;
    const JointSpec& joint = model.joints[j];
    ArmLink& link = links_[l];
    link.offset = Rigid::From(joint.origin);
    if (is_dof_link[l]) {
      link.dof = static_cast<int>(dof_joint_ids_.size());  // path order = topological order on the path
      link.type = joint.type;
      link.axis = joint.axis;
      dof_joint_ids_.push_back(joint.id);
      dof_joint_indices_.push_back(j);
    } else {
      link.offset = link.offset * Rigid::From(JointMotion(joint, state.joint_positions.at(j)));
    }
  }
  // dof_joint_ids_ were collected in link order, which is topological; the path's dofs are in the same order.
  const size_t n = dof_joint_ids_.size();
  lower_.resize(n);
  upper_.resize(n);
  velocity_.resize(n);
  Rigid accumulated;
  for (int l : path) {
    if (links_[l].parent < 0) continue;
    if (links_[l].dof >= 0) {
      const JointSpec& joint = model.joints[dof_joint_indices_[links_[l].dof]];
      const int i = links_[l].dof;
      dof_offsets_.push_back(accumulated * links_[l].offset);
      dof_types_.push_back(joint.type);
      dof_axes_.push_back(joint.axis);
      const bool unbounded = joint.type == JointType::kContinuous;
      lower_[i] = unbounded ? -EIGEN_PI : joint.lower;
      upper_[i] = unbounded ? EIGEN_PI : joint.upper;
      velocity_[i] = joint.velocity_limit > 0 ? joint.velocity_limit : 1.0;
      accumulated = Rigid();
    } else {
      accumulated = accumulated * links_[l].offset;
    }
  }
  tip_offset_ = accumulated;
  if (n == 0) ThrowInvalidArgument("arm_id: robot '" + robot_id + "' has no movable joint between its base and " + tip);
}

bool ArmModel::WithinLimits(const VecX& q, double tolerance) const {
  if (q.size() != static_cast<long>(dof())) return false;
  for (size_t i = 0; i < dof(); ++i) {
    if (!(q[i] >= lower_[i] - tolerance && q[i] <= upper_[i] + tolerance)) return false;
  }
  return true;
}

VecX ArmModel::Positions(const SceneState& state) const {
  VecX q(dof());
  for (size_t i = 0; i < dof(); ++i) q[i] = state.joint_positions.at(dof_joint_indices_[i]);
  return q;
}

void ArmModel::LinkTransforms(const Eigen::Ref<const VecX>& q, std::vector<Rigid>* out) const {
  out->resize(links_.size());
  for (size_t l = 0; l < links_.size(); ++l) {
    const ArmLink& link = links_[l];
    const Rigid& parent = link.parent < 0 ? base_ : (*out)[link.parent];
    if (link.parent < 0) {
      (*out)[l] = base_;
    } else if (link.dof < 0) {
      (*out)[l] = parent * link.offset;
    } else {
      (*out)[l] = parent * link.offset * JointRigid(link.type, link.axis, q[link.dof]);
    }
  }
}

Rigid ArmModel::TipTransform(const VecX& q) const {
  Rigid t = base_;
  for (size_t i = 0; i < dof(); ++i) t = t * dof_offsets_[i] * JointRigid(dof_types_[i], dof_axes_[i], q[i]);
  return t * tip_offset_;
}

Eigen::Matrix<double, 6, Eigen::Dynamic> ArmModel::Jacobian(const VecX& q) const {
  const size_t n = dof();
  std::vector<Vec3> origins(n), axes(n);
  Rigid t = base_;
  for (size_t i = 0; i < n; ++i) {
    t = t * dof_offsets_[i];
    origins[i] = t.translation;
    axes[i] = t.rotation * dof_axes_[i];
    t = t * JointRigid(dof_types_[i], dof_axes_[i], q[i]);
  }
  const Vec3 tip = (t * tip_offset_).translation;
  Eigen::Matrix<double, 6, Eigen::Dynamic> jacobian(6, n);
  for (size_t i = 0; i < n; ++i) {
    if (dof_types_[i] == JointType::kPrismatic) {
      jacobian.col(i) << axes[i], Vec3::Zero();
    } else {
      jacobian.col(i) << axes[i].cross(tip - origins[i]), axes[i];
    }
  }
  return jacobian;
}

}  // namespace graspsim::motion
