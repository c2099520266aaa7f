// The mutable part of a scene (MuJoCo's mjData), indexed like the SceneModel it belongs to.
#pragma once

#include <array>
#include <compare>
#include <cstdint>
#include <map>
#include <vector>

#include "core/math.h"
#include "world/model.h"
#include "world/simulation_params.h"

namespace graspsim {

// A free body's velocity: of its centre of mass and about it, both in the world frame.
struct BodyVelocity {
  Vec3 linear = Vec3::Zero();   // m/s
  Vec3 angular = Vec3::Zero();  // rad/s
};

// Identifies one persistent contact point: a surface sample of body_a pressing into body_b.
struct ContactKey {
  uint32_t body_a = 0, body_b = 0;  // indices into SceneModel::bodies
  uint64_t feature = 0;             // the sample on body_a (see collision/contact_finder.h)
  auto operator<=>(const ContactKey&) const = default;
};

struct SceneState {
  double time = 0;                      // simulation time, s
  uint64_t step = 0;                    // steps taken
  std::vector<Pose> body_poses;         // world pose of every body (links placed by forward kinematics)
  std::vector<double> joint_positions;  // rad or m, per joint (0 for fixed joints)
  std::vector<BodyVelocity> body_velocities;  // per body; used for free bodies (links: derived, kept zero)
  std::vector<double> joint_velocities;       // rad/s or m/s, per joint
  std::vector<bool> sleeping;                 // per body: a free body at rest, skipped until touched
  std::vector<double> rest_time;              // per body: s spent below the sleep speed
  // LuGre bristle deflection z per persistent contact, m, world; sorted by key, the order the contact finder
  // reports contacts in, so a step rebuilds it in order and finds each contact's bristle where the last lookup
  // ended (physics/simulation_contacts.cpp).
  std::vector<std::pair<ContactKey, Vec3>> bristles;
  std::map<size_t, JointActuator> actuators;  // by joint index: driven joints
  // Per tactile array, per sensing element (tactile/pad_elements.h order): the force the touching object
  // exerts on the pad, N, world frame; all zero when nothing touches. Sized by the simulation.
  std::vector<std::vector<Vec3>> pad_forces;
  // Per joint: the wrench the joint transmits from its parent side to its child side in the last sub-step (what
  // the child body and everything it carries receive through the joint: constraint and motor forces; an end
  // stop's velocity clamp is not among them), in the joint's child frame (the child body's frame):
  // {force N, torque N m about the frame's origin}.
  // The force/torque sensor reading (sensors/readings.h). Sized by the simulation; zero before the first step.
  std::vector<std::array<Vec3, 2>> joint_wrenches;
  // The contacts of the last sub-step, for viewers (world/snapshot_hub.h): where (world, m) and the force on the
  // first body (world, N); body_a's sample lies inside body_b (collision/contact_finder.h). Set by the simulation.
  struct Contact {
    uint32_t body_a = 0, body_b = 0;  // indices into SceneModel::bodies
    Vec3 point = Vec3::Zero();
    Vec3 force = Vec3::Zero();
  };
  std::vector<Contact> contacts;
};

// Places every link of robot number `robot` (index into model.robots) from its base pose and joint positions
// (parents before children). The model must be Reindex()ed.
void UpdateRobotLinkPoses(const SceneModel& model, size_t robot, SceneState* state);

// Transform of a joint's child frame relative to its joint frame at position q (rad or m).
Pose JointMotion(const JointSpec& joint, double q);
// The same for a joint given by its type and unit axis (hand models that keep their own joint records).
Pose JointMotion(JointType type, const Vec3& axis, double q);

}  // namespace graspsim
