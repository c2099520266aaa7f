// An arm of a scene as a kinematic chain (Drake's MultibodyPlant idea, small): the robot's joints from its base
// body to a tip body are the arm's degrees of freedom, in order; every other joint of the robot (a hand's
// fingers) is held at its position in the scene state, so the links it moves ride rigidly on their parent.
//
// Forward kinematics: the tip's world pose
//   T_tip(q) = T_base · Π_i [ O_i · M_i(q_i) ] · O_tip,
// O_i the constant transform from the previous dof's child frame to joint i's frame (joint origins, fixed joints
// and held joints in between), M_i the joint motion (a rotation about, or a translation along, the unit axis),
// O_tip from the last dof's child frame to the tip body. Units: m, rad.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "core/math.h"
#include "world/model.h"
#include "world/state.h"

namespace graspsim::motion {

using VecX = Eigen::VectorXd;

// A rigid transform as a rotation matrix (FK's inner loop multiplies many; matrices beat quaternions there).
struct Rigid {
  Mat3 rotation = Mat3::Identity();
  Vec3 translation = Vec3::Zero();

  Rigid operator*(const Rigid& b) const { return {rotation * b.rotation, rotation * b.translation + translation}; }
  Vec3 operator*(const Vec3& p) const { return rotation * p + translation; }
  Rigid Inverse() const { return {rotation.transpose(), -(rotation.transpose() * translation)}; }
  static Rigid From(const Pose& pose) { return {pose.orientation.toRotationMatrix(), pose.position}; }
  Pose ToPose() const { return {translation, Quat(rotation).normalized()}; }
};

// One body of the robot, placed relative to its parent body.
struct ArmLink {
  size_t body = 0;        // index into SceneModel::bodies
  std::string id;         // its body id, "<robot>/<link>"
  int parent = -1;        // index into ArmModel::links(); -1 for the base body
  Rigid offset;           // parent frame -> joint frame (held joints: their motion included)
  int dof = -1;           // the arm joint moving this link, -1 if rigid on its parent
  JointType type = JointType::kFixed;
  Vec3 axis = Vec3::UnitZ();
};

class ArmModel {
 public:
  // `robot_id`: a robot of `model`. `tip_body`: a body id of that robot ("<robot>/<link>"); empty picks
  // "<robot>/flange" when the robot has one, else the last body of its longest joint chain. The dofs are the
  // non-fixed, non-mimic joints on the path from the base to the tip. Joints off that path keep their
  // positions in `state`. Throws Error(kNotFound / kInvalidArgument) naming the robot or the body.
  ArmModel(const SceneModel& model, const SceneState& state, const std::string& robot_id,
           const std::string& tip_body = "");

  size_t dof() const { return dof_joint_ids_.size(); }
  const std::vector<std::string>& joint_ids() const { return dof_joint_ids_; }
  const std::vector<size_t>& joint_indices() const { return dof_joint_indices_; }  // into SceneModel::joints
  const VecX& lower() const { return lower_; }
  const VecX& upper() const { return upper_; }
  const VecX& velocity_limits() const { return velocity_; }  // rad/s or m/s (the URDF's; 1 where it gives none)
  const std::vector<ArmLink>& links() const { return links_; }
  const std::string& robot_id() const { return robot_id_; }
  const std::string& tip_body() const { return tip_body_id_; }
  int tip_link() const { return tip_link_; }
  const Rigid& base() const { return base_; }                 // world pose of the robot's base body
  const std::vector<Rigid>& dof_offsets() const { return dof_offsets_; }  // O_i
  const Rigid& tip_offset() const { return tip_offset_; }    // O_tip
  const std::vector<JointType>& dof_types() const { return dof_types_; }
  const std::vector<Vec3>& dof_axes() const { return dof_axes_; }

  bool WithinLimits(const VecX& q, double tolerance = 0) const;
  // The arm's joint positions in `state` (the start of a plan).
  VecX Positions(const SceneState& state) const;

  // World transform of every link (indexed like links()); *out is resized once and reused.
  void LinkTransforms(const Eigen::Ref<const VecX>& q, std::vector<Rigid>* out) const;
  Rigid TipTransform(const VecX& q) const;
  Pose TipPose(const VecX& q) const { return TipTransform(q).ToPose(); }
  // Geometric Jacobian of the tip (rows: linear velocity of the tip origin, angular velocity; world frame).
  Eigen::Matrix<double, 6, Eigen::Dynamic> Jacobian(const VecX& q) const;

 private:
  std::string robot_id_, tip_body_id_;
  std::vector<ArmLink> links_;
  int tip_link_ = 0;
  Rigid base_, tip_offset_;
  std::vector<Rigid> dof_offsets_;
  std::vector<JointType> dof_types_;
  std::vector<Vec3> dof_axes_;
  std::vector<std::string> dof_joint_ids_;
  std::vector<size_t> dof_joint_indices_;
  VecX lower_, upper_, velocity_;
};

// The motion of a joint as a Rigid (a rotation about `axis` or a translation along it).
Rigid JointRigid(JointType type, const Vec3& axis, double q);

}  // namespace graspsim::motion
