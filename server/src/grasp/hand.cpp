// The grasp hands: pre-shapes and finger closing of the built-in hand models.
#include "grasp/hand.h"

#include <algorithm>
#include <map>
#include <numbers>

#include "core/error.h"
#include "core/limits.h"
#include "import/robot_import.h"
#include "world/loaders.h"

namespace graspsim::grasp {
namespace {

constexpr double kPi = std::numbers::pi;

struct HandTable {
  std::vector<Preshape> preshapes;
  std::vector<FingerSpec> fingers;
  double roll_period;
};

// Pre-shapes and fingers per hand. Why these numbers:
// - PG70: "power" opens fully (35 mm per jaw), "pinch" half (15 mm) so small objects are taken without the
//   open jaws sweeping their surroundings. Each jaw closes on its own: the real gripper centres itself on the
//   object (the object slides until both jaws touch), which the kinematic model expresses by stopping each jaw
//   at its own contact; the contact geometry relative to the object is the same.
// - Barrett: "power" with fingers 1 and 2 side by side opposite finger 3, "spherical" at a 60 deg spread
//   (three fingers about 120 deg apart), "pinch" from bent fingers so the tips meet first.
// - SDH: the same three grasps with its rotation axis. "power" and "spherical" open the fingers outward
//   (proximal -0.6 rad, distal +0.3 rad: the fingertips 10 cm apart) so that the palm can reach objects
//   wider than the straight fingers' gap; "pinch" starts straight for small objects. Both flex joints of a
//   finger close at the same rate, as SCHUNK's own grasp controller does for cylindrical and spherical grasps.
const std::map<std::string, HandTable>& Tables() {
  static const std::map<std::string, HandTable> tables = {
      {"schunk_pg70",
       {{{"power", {{"finger_left_joint", 0.035}}}, {"pinch", {{"finger_left_joint", 0.015}}}},
        {{"left", {{"finger_left_joint", -1.0}}}, {"right", {{"finger_right_joint", -1.0}}}},
        kPi}},  // symmetric under a half turn about the approach
      {"barrett_bh8_282",
       {{{"power", {{"finger1_spread", 0.0}}},
         {"spherical", {{"finger1_spread", kPi / 3}}},
         {"pinch", {{"finger1_spread", 0.0}, {"finger1_flex", 0.6}, {"finger2_flex", 0.6}, {"finger3_flex", 0.6}}}},
        {{"finger1", {{"finger1_flex", 1.0}}}, {"finger2", {{"finger2_flex", 1.0}}}, {"finger3", {{"finger3_flex", 1.0}}}},
        2 * kPi}},
      {"schunk_sdh2",
       {{{"power",
          {{"finger1_rotation", 0.0}, {"finger1_proximal_joint", -0.6}, {"finger1_distal_joint", 0.3},
           {"finger2_proximal_joint", -0.6}, {"finger2_distal_joint", 0.3}, {"finger3_proximal_joint", -0.6},
           {"finger3_distal_joint", 0.3}}},
         {"spherical",
          {{"finger1_rotation", kPi / 3}, {"finger1_proximal_joint", -0.6}, {"finger1_distal_joint", 0.3},
           {"finger2_proximal_joint", -0.6}, {"finger2_distal_joint", 0.3}, {"finger3_proximal_joint", -0.6},
           {"finger3_distal_joint", 0.3}}},
         {"pinch", {{"finger1_rotation", 0.0}}}},
        {{"finger1", {{"finger1_proximal_joint", 1.0}, {"finger1_distal_joint", 1.0}}},
         {"finger2", {{"finger2_proximal_joint", 1.0}, {"finger2_distal_joint", 1.0}}},
         {"finger3", {{"finger3_proximal_joint", 1.0}, {"finger3_distal_joint", 1.0}}}},
        2 * kPi}},
  };
  return tables;
}

std::string Join(const std::vector<std::string>& names) {
  std::string list;
  for (const std::string& name : names) list += (list.empty() ? "" : ", ") + name;
  return list;
}

}  // namespace

const std::vector<std::string>& HandNames() {
  static const std::vector<std::string> names = [] {
    std::vector<std::string> out;
    for (const auto& [name, table] : Tables()) out.push_back(name);
    return out;
  }();
  return names;
}

const std::string& HandUrdf(const std::string& name) { return BuiltinModelUrdf(name); }

HandSpec LoadHand(const std::string& field, const std::string& name) {
  const auto table = Tables().find(name);
  if (table == Tables().end()) {
    ThrowInvalidArgument(field + ": '" + name.substr(0, 80) + "' is not a known hand; known: " + Join(HandNames()));
  }
  HandSpec hand;
  hand.name = name;
  hand.robot = LoadUrdf(HandUrdf(name), nullptr, Limits());
  hand.preshapes = table->second.preshapes;
  hand.fingers = table->second.fingers;
  hand.roll_period = table->second.roll_period;
  return hand;
}

const Preshape& FindPreshape(const HandSpec& hand, const std::string& field, const std::string& name) {
  if (name.empty()) return hand.preshapes.front();
  for (const Preshape& preshape : hand.preshapes) {
    if (preshape.name == name) return preshape;
  }
  std::vector<std::string> names;
  for (const Preshape& preshape : hand.preshapes) names.push_back(preshape.name);
  ThrowInvalidArgument(field + ": '" + name.substr(0, 80) + "' is not a pre-shape of " + hand.name +
                       "; its pre-shapes: " + Join(names));
}

}  // namespace graspsim::grasp
