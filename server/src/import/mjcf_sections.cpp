// MJCF's sections after the worldbody: mimic joints from <equality>, effort limits from <actuator>, notes for the
// sections graspsim does not import; and <compiler>'s mass bounds and total mass.
#include "import/mjcf_sections.h"

#include <algorithm>
#include <cmath>

#include "core/error.h"

namespace graspsim::import::mjcf {

void CompilerMasses(const Compiler& compiler, FileInertials* inertials) {
  double total = 0;
  for (auto& [link, inertial] : *inertials) {
    if (inertial.massless || link == "world") continue;
    if (compiler.boundmass > 0 && inertial.mass < compiler.boundmass) inertial.mass = compiler.boundmass;
    if (compiler.boundinertia > 0) {
      for (int axis = 0; axis < 3; ++axis) {
        inertial.inertia(axis, axis) = std::max(inertial.inertia(axis, axis), compiler.boundinertia);
      }
    }
    total += inertial.mass;
  }
  if (compiler.settotalmass > 0 && total > 0) {
    const double scale = compiler.settotalmass / total;
    for (auto& [link, inertial] : *inertials) {
      if (inertial.massless || link == "world") continue;
      inertial.mass *= scale;
      inertial.inertia *= scale;
    }
  }
}

// <equality><joint> as mimic joints, actuator force ranges as effort limits, and a note per kind not imported.
void Sections(const Document& document, const std::map<std::string, std::string>& single_joints,
              RobotDescription* description, Warnings* warnings) {
  const tinyxml2::XMLElement& root = document.root();
  const auto joint_of = [&](const std::string& mjcf_name) -> JointSpec* {
    const auto it = single_joints.find(mjcf_name);
    if (it == single_joints.end()) return nullptr;
    for (JointSpec& joint : description->joints) {
      if (joint.id == it->second) return &joint;
    }
    return nullptr;
  };
  for (const tinyxml2::XMLElement* section = root.FirstChildElement(); section != nullptr;
       section = section->NextSiblingElement()) {
    const std::string tag = section->Name();
    if (tag == "equality") {
      for (const tinyxml2::XMLElement* e = section->FirstChildElement(); e != nullptr; e = e->NextSiblingElement()) {
        const std::string kind = e->Name();
        const std::string field = "mjcf: <equality><" + kind + "> (line " + std::to_string(e->GetLineNum()) + ")";
        if (kind != "joint") {
          warnings->NoteOnce("mjcf: <equality><" + kind + ">", "present", "not imported (graspsim models no loops)");
          continue;
        }
        const Element equality = document.Read(*e, "", field);
        if (!equality.Bool("active", true)) continue;
        const std::string follower_name = equality.String("joint1"), leader_name = equality.String("joint2");
        std::vector<double> c = equality.Numbers("polycoef", 1, 5);
        if (c.empty()) c = {0, 1};
        c.resize(5, 0.0);
        JointSpec* follower = joint_of(follower_name);
        JointSpec* leader = joint_of(leader_name);
        std::string problem;
        if (follower == nullptr) problem = "joint1 " + Quoted(follower_name) + " is not a hinge or slide joint";
        else if (leader == nullptr) problem = "joint2 " + Quoted(leader_name) + " is not a hinge or slide joint";
        else if (leader == follower) problem = "a joint cannot follow itself";
        else if (c[2] != 0 || c[3] != 0 || c[4] != 0) problem = "polycoef " + Quoted(equality.String("polycoef")) + " is not linear";
        else if (follower->mimic || leader->mimic) problem = "a joint in a chain of mimics";
        if (!problem.empty()) {
          warnings->Repair(field, problem, "dropped");
          continue;
        }
        follower->mimic = MimicSpec{leader->id, c[1], c[0]};
      }
    } else if (tag == "actuator") {
      size_t count = 0;
      for (const tinyxml2::XMLElement* e = section->FirstChildElement(); e != nullptr; e = e->NextSiblingElement()) {
        ++count;
        const Element actuator = document.Read(*e, "", "mjcf: <actuator><" + std::string(e->Name()) + ">");
        JointSpec* joint = joint_of(actuator.String("joint"));
        if (joint == nullptr || joint->effort_limit > 0) continue;
        const std::vector<double> force = actuator.Numbers("forcerange", 2, 2);
        const bool automatic = document.compiler().autolimits;
        if (!force.empty() && actuator.Bool("forcelimited", automatic, automatic)) {
          joint->effort_limit = std::max(std::abs(force[0]), std::abs(force[1]));
        } else if (std::string(e->Name()) == "motor") {
          const std::vector<double> control = actuator.Numbers("ctrlrange", 2, 2);
          const std::vector<double> gear = actuator.Numbers("gear", 1, 6);
          if (!control.empty() && actuator.Bool("ctrllimited", automatic, automatic)) {
            joint->effort_limit = std::abs(gear.empty() ? 1.0 : gear[0]) * std::max(std::abs(control[0]), std::abs(control[1]));
          }
        }
      }
      warnings->NoteOnce("mjcf: <actuator>", std::to_string(count) + " element(s)",
                         "not imported (force ranges set joint effort limits)");
    } else if (tag == "tendon" || tag == "sensor" || tag == "contact" || tag == "deformable" || tag == "skin") {
      if (section->FirstChildElement() != nullptr) warnings->NoteOnce("mjcf: <" + tag + ">", "present", "not imported");
    }
  }
}

}  // namespace graspsim::import::mjcf
