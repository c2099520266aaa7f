// Hands for grasp planning: a built-in robot description (server/models) plus what the planner needs to know
// about it that a URDF does not say: named pre-shapes and which joints close which finger.
//
// Conventions every grasp hand follows (its URDF header says so): the root link's +z is the approach
// direction, out of the palm toward the fingertips; the hand pose is the root link's pose.
#pragma once

#include <string>
#include <utility>
#include <vector>

#include "world/model.h"

namespace graspsim::grasp {

// Joint positions (rad or m) of the open hand before it approaches: the driven joints by URDF name; joints
// that mimic one of them follow through the mimic relation, every other joint stays at 0.
struct Preshape {
  std::string name;  // "pinch", "power", "spherical"
  std::vector<std::pair<std::string, double>> joint_positions;
};

// One finger closing: its driven joints move together, each at its rate (dq/ds, rad or m per unit of the
// closing parameter s, signed toward closing), until a link of the finger touches something or a joint reaches
// its limit. Joints that mimic a driven joint follow it. The finger stops as a whole at its first contact.
struct FingerSpec {
  std::string name;
  std::vector<std::pair<std::string, double>> joint_rates;
};

struct HandSpec {
  std::string name;  // the built-in model's name, e.g. "schunk_pg70"
  RobotDescription robot;
  std::vector<Preshape> preshapes;  // the first is the default
  std::vector<FingerSpec> fingers;
  // Rolls about the approach are taken in [0, roll_period): pi for a hand that looks the same after a half
  // turn (a parallel gripper), 2 pi otherwise.
  double roll_period = 0;
};

// The hands the planner knows, by built-in model name.
const std::vector<std::string>& HandNames();

// The hand and its URDF text (for the grasp-set key). Throws Error(kInvalidArgument) naming `field` and the
// value and listing the known hands when `name` is not one of HandNames().
HandSpec LoadHand(const std::string& field, const std::string& name);
const std::string& HandUrdf(const std::string& name);

// The pre-shape named `name` ("" = the hand's default); throws Error(kInvalidArgument) naming `field` and the
// value and listing the hand's pre-shapes otherwise.
const Preshape& FindPreshape(const HandSpec& hand, const std::string& field, const std::string& name);

}  // namespace graspsim::grasp
