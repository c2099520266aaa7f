#include "import/urdf_repairs.h"

#include <charconv>
#include <cstdlib>
#include <set>
#include <sstream>

#include "core/error.h"
#include "core/format.h"
#include "import/loader_common.h"
#include "import/primitive_shapes.h"

namespace graspsim::import {
namespace {

constexpr size_t kMaxNameLength = 64;
// A plane (PyBullet's <plane normal>) as a box: 200 m square (PyBullet's own plane.urdf uses a 200 m box) and
// 0.1 m thick, its top face on the plane.
constexpr double kPlaneSide = 200;

// Numbers of an attribute; empty when absent or not numbers (urdfdom then reports it).
std::vector<double> Numbers(const TiXmlElement& e, const char* attribute) {
  std::vector<double> values;
  const char* text = e.Attribute(attribute);
  if (text == nullptr) return values;
  std::istringstream words(text);
  for (std::string word; words >> word;) {
    double v = 0;
    const auto [end, error] = std::from_chars(word.data(), word.data() + word.size(), v);
    if (error != std::errc() || end != word.data() + word.size()) return {};
    values.push_back(v);
  }
  return values;
}

Pose OriginOf(const TiXmlElement& collision) {
  Pose pose;
  if (const TiXmlElement* origin = collision.FirstChildElement("origin"); origin != nullptr) {
    const std::vector<double> xyz = Numbers(*origin, "xyz"), rpy = Numbers(*origin, "rpy");
    if (xyz.size() == 3) pose.position = Vec3(xyz[0], xyz[1], xyz[2]);
    if (rpy.size() == 3) pose.orientation = QuatFromRpy(rpy[0], rpy[1], rpy[2]);
  }
  return pose;
}

// Renames every link and joint whose name graspsim refuses, and every reference to it.
void RepairNames(TiXmlElement* robot, std::vector<ImportWarning>* warnings) {
  std::map<std::string, std::string> links, joints;
  std::set<std::string> taken;
  for (const char* tag : {"link", "joint"}) {
    for (TiXmlElement* e = robot->FirstChildElement(tag); e != nullptr; e = e->NextSiblingElement(tag)) {
      if (const char* name = e->Attribute("name"); name != nullptr) taken.insert(name);
    }
  }
  for (const char* tag : {"link", "joint"}) {
    auto& renames = std::string(tag) == "link" ? links : joints;
    for (TiXmlElement* e = robot->FirstChildElement(tag); e != nullptr; e = e->NextSiblingElement(tag)) {
      const char* name = e->Attribute("name");
      if (name == nullptr || *name == '\0' || SanitiseName(name, nullptr) == name) continue;
      std::string fixed = SanitiseName(name, nullptr);
      for (int n = 2; taken.count(fixed); ++n) fixed = SanitiseName(name, nullptr).substr(0, kMaxNameLength - 4) + "_" + std::to_string(n);
      taken.insert(fixed);
      renames[name] = fixed;
      e->SetAttribute("name", fixed);
      warnings->push_back({std::string("urdf: ") + tag + " name", Quoted(name),
                           "renamed " + Quoted(fixed) + " (names are 1..64 letters, digits, '_', '-', '.')"});
    }
  }
  if (links.empty() && joints.empty()) return;
  const auto rename = [](TiXmlElement* e, const char* attribute, const std::map<std::string, std::string>& names) {
    const char* value = e != nullptr ? e->Attribute(attribute) : nullptr;
    if (value == nullptr) return;
    if (const auto it = names.find(value); it != names.end()) e->SetAttribute(attribute, it->second);
  };
  for (TiXmlElement* j = robot->FirstChildElement("joint"); j != nullptr; j = j->NextSiblingElement("joint")) {
    rename(j->FirstChildElement("parent"), "link", links);
    rename(j->FirstChildElement("child"), "link", links);
    rename(j->FirstChildElement("mimic"), "joint", joints);
  }
  for (TiXmlElement* t = robot->FirstChildElement("tactile_array"); t != nullptr;
       t = t->NextSiblingElement("tactile_array")) {
    rename(t, "link", links);
  }
}

// Takes out collision geometry urdfdom does not know, adding what graspsim can model to extra_collision.
void RepairCollisions(TiXmlElement* robot, UrdfRepairs* repairs, std::vector<ImportWarning>* warnings) {
  for (TiXmlElement* link = robot->FirstChildElement("link"); link != nullptr; link = link->NextSiblingElement("link")) {
    const std::string link_name = link->Attribute("name") != nullptr ? link->Attribute("name") : "";
    for (TiXmlElement* c = link->FirstChildElement("collision"); c != nullptr;) {
      TiXmlElement* next = c->NextSiblingElement("collision");
      const TiXmlElement* geometry = c->FirstChildElement("geometry");
      const TiXmlElement* shape = geometry != nullptr ? geometry->FirstChildElement() : nullptr;
      const std::string kind = shape != nullptr ? shape->ValueStr() : "";
      if (shape == nullptr || kind == "box" || kind == "sphere" || kind == "cylinder" || kind == "mesh") {
        c = next;
        continue;
      }
      const std::string element = "urdf: link " + Quoted(link_name) + " collision <" + kind + ">";
      const Pose origin = OriginOf(*c);
      auto& extra = repairs->extra_collision[link_name];
      if (kind == "plane") {
        std::vector<double> n = Numbers(*shape, "normal");
        Vec3 normal = n.size() == 3 ? Vec3(n[0], n[1], n[2]) : Vec3::UnitZ();
        normal = normal.norm() > 1e-12 && normal.allFinite() ? normal.normalized() : Vec3::UnitZ();
        const Geometry box = PlaneBox(normal, kPlaneSide, kPlaneSide, origin);
        extra.push_back(box);
        warnings->push_back({element, "normal " + FormatNumber(normal.x()) + " " + FormatNumber(normal.y()) + " " +
                                          FormatNumber(normal.z()),
                             "a 200 m square box 0.1 m thick, its top face on the plane"});
      } else if (kind == "capsule") {
        const std::vector<double> r = Numbers(*shape, "radius"), l = Numbers(*shape, "length");
        if (r.size() == 1 && l.size() == 1 && r[0] > 0 && l[0] >= 0) {
          for (const Geometry& part : CapsuleGeometries(r[0], std::max(l[0], 1e-9), origin)) extra.push_back(part);
          warnings->push_back({element, "radius " + FormatNumber(r[0]) + " length " + FormatNumber(l[0]),
                               "a cylinder and two spheres (the same solid)"});
        } else {
          ThrowInvalidArgument(element + ": radius and length must be one positive number each");
        }
      } else {
        warnings->push_back({element, kind, "geometry graspsim does not model: collision element dropped"});
      }
      link->RemoveChild(c);
      c = next;
    }
  }
}

// Numbers as PyBullet's parser reads them (C's strtod on each word, the first three words of a vector): "0.07,",
// "-1.57.", a vector of four numbers and leftover xacro "$(optenv X 0.1)" load there, and so load here with a
// warning. Only attributes URDF defines as numbers are touched.
void RepairNumbers(TiXmlElement* robot, std::vector<ImportWarning>* warnings) {
  static const std::set<std::string> kVectors = {"xyz", "rpy", "scale", "size"};
  static const std::set<std::string> kScalars = {"value", "ixx", "ixy", "ixz", "iyy", "iyz", "izz", "radius",
                                                 "length", "lower", "upper", "velocity", "effort", "multiplier",
                                                 "offset", "damping", "friction"};
  std::vector<TiXmlElement*> pending = {robot};
  while (!pending.empty()) {
    TiXmlElement* e = pending.back();
    pending.pop_back();
    for (TiXmlElement* child = e->FirstChildElement(); child != nullptr; child = child->NextSiblingElement()) {
      if (child->ValueStr() != "tactile_array") pending.push_back(child);  // graspsim's own element stays strict
    }
    for (TiXmlAttribute* a = e->FirstAttribute(); a != nullptr; a = a->Next()) {
      const std::string name = a->Name();
      const bool vector = kVectors.count(name) > 0;
      if (!vector && kScalars.count(name) == 0) continue;
      std::istringstream words(a->ValueStr());
      std::vector<std::string> parts;
      for (std::string word; words >> word;) parts.push_back(word);
      const size_t wanted = vector ? 3 : 1;
      bool changed = parts.size() > wanted;
      std::string repaired;
      for (size_t i = 0; i < std::min(parts.size(), wanted); ++i) {
        const char* begin = parts[i].c_str();
        char* end = nullptr;
        const double v = std::strtod(begin, &end);
        const bool whole = end != begin && *end == '\0';
        changed = changed || !whole;
        repaired += (i ? " " : "") + (whole ? parts[i] : FormatNumber(end == begin ? 0.0 : v));
      }
      if (!changed || parts.size() < wanted) continue;  // too few numbers: urdfdom names the element
      warnings->push_back({"urdf: <" + e->ValueStr() + "> " + name, Quoted(a->ValueStr()),
                           "read as " + Quoted(repaired) + " (as PyBullet's parser reads it)"});
      a->SetValue(repaired);
    }
  }
}

// Limits as PyBullet reads them: lower above upper, or no <limit> at all, means an unlimited joint; velocity and
// effort may be left out (0 = none given, no warning: nothing the file says is changed).
void RepairLimits(TiXmlElement* robot, UrdfRepairs* repairs, std::vector<ImportWarning>* warnings) {
  for (TiXmlElement* j = robot->FirstChildElement("joint"); j != nullptr; j = j->NextSiblingElement("joint")) {
    const char* type_text = j->Attribute("type");
    const std::string type = type_text != nullptr ? type_text : "";
    const bool limited = type == "revolute" || type == "prismatic";
    TiXmlElement* limit = j->FirstChildElement("limit");
    double lower = 0, upper = 0;
    const bool bounded = limit != nullptr && limit->QueryDoubleAttribute("lower", &lower) == TIXML_SUCCESS &&
                         limit->QueryDoubleAttribute("upper", &upper) == TIXML_SUCCESS;
    const bool unlimited = limited && (limit == nullptr || (bounded && lower > upper));
    if (limit == nullptr && !unlimited) continue;
    if (limit == nullptr) limit = static_cast<TiXmlElement*>(j->InsertEndChild(TiXmlElement("limit")));
    for (const char* attribute : {"velocity", "effort"}) {
      if (limit->Attribute(attribute) != nullptr) continue;
      limit->SetAttribute(attribute, "0");
      repairs->document_changed = true;
    }
    if (!unlimited) continue;
    const std::string joint = "urdf: joint " + Quoted(j->Attribute("name") != nullptr ? j->Attribute("name") : "");
    const std::string found = bounded ? "lower " + FormatNumber(lower) + " > upper " + FormatNumber(upper) : "no <limit>";
    if (type == "revolute") {
      j->SetAttribute("type", "continuous");
      warnings->push_back({joint + " limit", found, "an unlimited joint: continuous"});
    } else {
      limit->SetAttribute("lower", "-1000");
      limit->SetAttribute("upper", "1000");
      warnings->push_back({joint + " limit", found, "an unlimited joint: ±1000 m"});
    }
  }
}

// Ball and floating joints become graspsim joint chains; urdfdom is told they are fixed.
void RepairJoints(TiXmlElement* robot, UrdfRepairs* repairs, std::vector<ImportWarning>* warnings) {
  for (TiXmlElement* j = robot->FirstChildElement("joint"); j != nullptr; j = j->NextSiblingElement("joint")) {
    const char* type = j->Attribute("type");
    const char* name = j->Attribute("name");
    if (type == nullptr || name == nullptr) continue;
    const std::string kind = type;
    std::string chain, action;
    if (kind == "spherical" || kind == "ball") {
      chain = "ball";
      action = "three revolute joints about x, y, z (" + std::string(name) + "_x, _y, _z)";
    } else if (kind == "floating") {
      chain = "free";
      action = "three prismatic and three revolute joints (" + std::string(name) + "_px ... _z): a floating base";
    } else {
      continue;
    }
    repairs->chain_joints[name] = chain;
    j->SetAttribute("type", "fixed");
    warnings->push_back({"urdf: joint " + Quoted(name) + " type", kind, action});
  }
}

}  // namespace

UrdfRepairs RepairUrdfDocument(TiXmlElement* robot, std::vector<ImportWarning>* warnings) {
  UrdfRepairs repairs;
  const size_t warned = warnings->size();
  RepairNames(robot, warnings);
  RepairNumbers(robot, warnings);
  RepairLimits(robot, &repairs, warnings);
  RepairCollisions(robot, &repairs, warnings);
  RepairJoints(robot, &repairs, warnings);
  repairs.document_changed = repairs.document_changed || warnings->size() > warned;  // every other change warns
  return repairs;
}

}  // namespace graspsim::import
