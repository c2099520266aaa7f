// MJCF text → RobotDescription (ImportMjcf): the <worldbody> is the root link "world", each <body> a link, its
// joints graspsim joints. graspsim's child frame is the joint frame, while MJCF places joints inside the body
// (joint pos); each MJCF joint therefore moves an intermediate link at the joint's anchor, and the body's own link
// hangs from the last of them by a fixed joint when the anchor is not the body origin. Every MJCF body frame is
// then a link frame under the body's name, so forward kinematics matches MuJoCo's exactly.
#include <algorithm>
#include <cctype>
#include <cmath>
#include <map>
#include <set>
#include <string>
#include <vector>

#include "core/error.h"
#include "core/format.h"
#include "core/validate.h"
#include "import/loader_common.h"
#include "import/mjcf_document.h"
#include "import/mjcf_geometry.h"
#include "import/mjcf_sections.h"

namespace graspsim {
namespace import::mjcf {
namespace {

// A slide joint without limits: graspsim's prismatic joints are limited (as AppendFreeJoint's).
constexpr double kUnlimitedSlide = 1e3;  // m
constexpr size_t kMaxNameLength = 64;

std::string Format(double value) { return FormatNumber(value); }

struct Child {
  const tinyxml2::XMLElement* xml;
  Pose frame;               // the enclosing <frame>s' pose in the body frame
  std::string child_class;  // the class elements without their own take
};

class Builder {
 public:
  Builder(const std::string& text, const FileLookup& files, const ImportOptions& options, const Limits& limits,
          std::vector<ImportWarning>* warnings)
      : document_(text, files),
        options_(options),
        limits_(limits),
        warnings_(options.strict, warnings),
        warnings_vector_(warnings),
        meshes_(files, limits),
        geoms_(document_, options, limits, &meshes_, &warnings_) {}

  RobotDescription Build() {
    const tinyxml2::XMLElement& root = document_.root();
    description_.name = root.Attribute("model") != nullptr ? root.Attribute("model") : "mjcf";
    description_.root_link = "world";
    link_names_.insert("world");
    BodySpec world;
    world.id = "world";
    world.motion = BodyMotion::kArticulated;
    std::vector<Child> bodies;
    for (const tinyxml2::XMLElement* e = root.FirstChildElement("worldbody"); e != nullptr;
         e = e->NextSiblingElement("worldbody")) {
      std::vector<Child> children;
      Collect(*e, Pose{}, "", 0, &children);
      size_t geom_index = 0;
      for (const Child& child : children) {
        const std::string tag = child.xml->Name();
        if (tag == "geom") {
          const Element geom = document_.Read(*child.xml, child.child_class,
                                              GeomField("mjcf: worldbody", *child.xml, geom_index++));
          GeomResult result = geoms_.Read(geom, child.frame, false);
          world.collision.insert(world.collision.end(), result.collision.begin(), result.collision.end());
        } else if (tag == "body") {
          bodies.push_back(child);
        } else if (tag == "joint" || tag == "freejoint") {
          ThrowInvalidArgument("mjcf: worldbody has a <" + tag + "> (line " + std::to_string(child.xml->GetLineNum()) +
                               "); joints belong in bodies");
        } else {
          Other(tag);
        }
      }
    }
    // Welded to the world at base_pose, the worldbody's mass would never matter: massless by design, like the
    // links of a joint chain (no repair, no warning; MuJoCo's world body has no mass either).
    FileInertial massless;
    massless.field = "mjcf: worldbody";
    massless.massless = true;
    inertials_["world"] = massless;
    AddLink(std::move(world));
    for (const Child& body : bodies) Body(body, "world", Pose{}, 1);
    meshes_.ThrowIfMissing("mjcf");
    Sections(document_, single_joints_, &description_, &warnings_);
    CompilerMasses(document_.compiler(), &inertials_);
    ResolveInertials("mjcf", inertials_, options_, &description_, warnings_vector_);
    return std::move(description_);
  }

 private:
  static std::string GeomField(const std::string& owner, const tinyxml2::XMLElement& xml, size_t index) {
    const char* name = xml.Attribute("name");
    return owner + " geom " + (name != nullptr ? Quoted(name) : std::to_string(index));
  }

  // A body's (or frame's) children, with <frame>s flattened into their poses and child classes.
  void Collect(const tinyxml2::XMLElement& parent, const Pose& frame, const std::string& child_class, int depth,
               std::vector<Child>* out) {
    for (const tinyxml2::XMLElement* e = parent.FirstChildElement(); e != nullptr; e = e->NextSiblingElement()) {
      if (std::string(e->Name()) == "frame" && depth < 100) {
        const Element element(*e, nullptr, "mjcf: <frame> (line " + std::to_string(e->GetLineNum()) + ")");
        const char* cc = e->Attribute("childclass");
        Collect(*e, frame * FramePose(element, document_.compiler()), cc != nullptr ? cc : child_class, depth + 1, out);
      } else {
        out->push_back({e, frame, child_class});
      }
    }
  }

  void Other(const std::string& tag) {
    if (tag == "site") {
      warnings_.NoteOnce("mjcf: <site>", "present", "not imported (graspsim reports link poses; sites are not links)");
    } else if (tag == "camera" || tag == "light" || tag == "inertial" || tag == "plugin") {
      // cameras and lights are not part of the robot; <inertial> is read by Body
    } else {
      warnings_.NoteOnce("mjcf: <" + tag + ">", "present", "not imported");
    }
  }

  // `generated`: a name the loader made up (a joint's link, a weld), renamed without a warning.
  std::string UniqueName(const std::string& wanted, const std::string& field, std::set<std::string>* used,
                         bool generated = false) {
    std::string name = SanitiseName(wanted, nullptr);
    if (name != wanted && !generated) {
      warnings_.Repair(field + " name", Quoted(wanted), "renamed " + Quoted(name) + " (graspsim names are 1..64 of "
                                                        "letters, digits, '_', '-', '.')");
    }
    if (!used->insert(name).second) {
      const std::string base = name.substr(0, kMaxNameLength - 4);
      for (int k = 2; !used->insert(name = base + "_" + std::to_string(k)).second; ++k) {
      }
      if (!generated) {
        warnings_.Repair(field + " name", Quoted(wanted), "renamed " + Quoted(name) + " (the name was taken)");
      }
    }
    return name;
  }

  void AddLink(BodySpec link) {
    if (description_.links.size() >= limits_.max_bodies_per_scene) {
      ThrowResourceExhausted("mjcf: the model has more than " + std::to_string(limits_.max_bodies_per_scene) +
                             " links (bodies and the links of their joints); the limit is " +
                             std::to_string(limits_.max_bodies_per_scene));
    }
    link.motion = BodyMotion::kArticulated;
    description_.links.push_back(std::move(link));
  }

  void AddChainLink(const std::string& name) {
    BodySpec link;
    link.id = name;
    AddLink(std::move(link));
    FileInertial massless;
    massless.massless = true;
    massless.field = "mjcf: link " + Quoted(name);
    inertials_[name] = massless;
  }

  // `parent_global`: the parent body's frame in the world at zero positions (for coordinate="global").
  void Body(const Child& item, const std::string& parent_link, const Pose& parent_global, int depth);
  FileInertial ReadInertial(const Element& inertial, const Pose& frame) const;
  // Appends the joint (hinge, slide, ball, free) from `parent` to `child` (already a link) at `origin`.
  void Joint(const Element& joint, const std::string& type, const std::string& id, const std::string& parent,
             const std::string& child, const Pose& origin, const Vec3& axis);

  Document document_;
  const ImportOptions& options_;
  const Limits& limits_;
  Warnings warnings_;
  std::vector<ImportWarning>* warnings_vector_;
  MeshFiles meshes_;
  GeomReader geoms_;
  RobotDescription description_;
  FileInertials inertials_;
  std::set<std::string> link_names_, joint_names_;
  std::map<std::string, std::string> single_joints_;  // MJCF name of a hinge or slide → its joint id
  size_t body_count_ = 0, joint_count_ = 0;
};

void Builder::Body(const Child& item, const std::string& parent_link, const Pose& parent_global, int depth) {
  const tinyxml2::XMLElement& xml = *item.xml;
  const size_t index = ++body_count_;  // MuJoCo's body id: depth first, world = 0
  const char* raw = xml.Attribute("name");
  const std::string wanted = raw != nullptr && *raw != '\0' ? std::string(raw) : "body" + std::to_string(index);
  const std::string field = "mjcf: body " + Quoted(wanted);
  const std::string name = UniqueName(wanted, field, &link_names_);
  const char* own_class = xml.Attribute("childclass");
  const std::string child_class = own_class != nullptr ? std::string(own_class) : item.child_class;
  // Global coordinates (MuJoCo 2.3.2 and older): the body's pose and everything inside it are in the world frame;
  // the children's frame re-expresses them in the body frame.
  const bool global = document_.compiler().global;
  // (item.frame is then the parent's inverse world pose, so body_pose is local either way.)
  const Pose body_pose = item.frame * FramePose(Element(xml, nullptr, field), document_.compiler());
  const Pose body_global = parent_global * body_pose;
  CheckFinite(field + " pos", body_pose.position);

  std::vector<Child> children;
  Collect(xml, global ? body_global.Inverse() : Pose{}, child_class, 0, &children);
  std::vector<const Child*> joints, bodies;
  const Child* inertial_xml = nullptr;
  for (const Child& child : children) {
    const std::string tag = child.xml->Name();
    if (tag == "joint" || tag == "freejoint") joints.push_back(&child);
    if (tag == "body") bodies.push_back(&child);
    if (tag == "inertial") {
      if (inertial_xml != nullptr) ThrowInvalidArgument(field + " has two <inertial> elements");
      inertial_xml = &child;
    }
    if (tag != "joint" && tag != "freejoint" && tag != "body" && tag != "geom") Other(tag);
  }

  // Geometry and mass first: the body's link must exist before its joints are appended.
  const InertiaFromGeom from_geom = document_.compiler().inertia_from_geom;
  const bool with_mass =
      from_geom == InertiaFromGeom::kTrue || (from_geom == InertiaFromGeom::kAuto && inertial_xml == nullptr);
  BodySpec link;
  link.id = name;
  std::vector<Inertial> masses;
  size_t geom_index = 0;
  for (const Child& child : children) {
    if (std::string(child.xml->Name()) != "geom") continue;
    const Element geom = document_.Read(*child.xml, child.child_class, GeomField(field, *child.xml, geom_index++));
    GeomResult result = geoms_.Read(geom, child.frame, with_mass);
    link.collision.insert(link.collision.end(), result.collision.begin(), result.collision.end());
    if (result.has_mass) masses.push_back(result.mass);
  }
  if (with_mass && !masses.empty()) {  // MuJoCo's semantics: the geoms' mass properties are the file's inertial
    FileInertial combined;
    combined.field = field + " inertia from geoms";
    Vec3 moment = Vec3::Zero();
    for (const Inertial& m : masses) {
      combined.mass += m.mass;
      moment += m.mass * m.center_of_mass;
    }
    const Vec3 com = combined.mass > 0 ? Vec3(moment / combined.mass) : Vec3::Zero();
    for (const Inertial& m : masses) {
      const Vec3 d = m.center_of_mass - com;
      combined.inertia += m.inertia + m.mass * (d.squaredNorm() * Mat3::Identity() - d * d.transpose());
    }
    combined.origin.position = com;
    inertials_[name] = combined;
  } else if (inertial_xml != nullptr) {
    inertials_[name] = ReadInertial(Element(*inertial_xml->xml, nullptr, field + " inertial"), inertial_xml->frame);
  }

  // Joints: each moves an intermediate link at its anchor; the body hangs from the last one.
  std::string parent = parent_link;
  Pose body_in_parent = body_pose;  // the body frame (at zero positions) in `parent`'s frame
  for (size_t k = 0; k < joints.size(); ++k) {
    const Child& child = *joints[k];
    const size_t joint_index = joint_count_++;
    const char* joint_raw = child.xml->Attribute("name");
    const std::string joint_wanted =
        joint_raw != nullptr && *joint_raw != '\0' ? std::string(joint_raw) : "joint" + std::to_string(joint_index);
    const std::string joint_field = field + " joint " + Quoted(joint_wanted);
    const Element joint = document_.Read(*child.xml, child.child_class, joint_field);
    const std::string type = std::string(child.xml->Name()) == "freejoint" ? "free" : joint.String("type", "hinge");
    const std::string id = UniqueName(joint_wanted, joint_field, &joint_names_);
    Vec3 pos = type == "free" ? Vec3::Zero() : Vec3(child.frame * joint.Vector("pos", Vec3::Zero()));
    Vec3 axis = child.frame.orientation * joint.Vector("axis", Vec3::UnitZ());
    CheckFinite(joint_field + " pos", pos);
    const bool last = k + 1 == joints.size();
    const bool body_is_child = last && pos.isZero(0);
    const std::string child_link =
        body_is_child ? name : UniqueName(name + "__" + id, joint_field + " link", &link_names_, true);
    if (body_is_child) {
      AddLink(std::move(link));
    } else {
      AddChainLink(child_link);
    }
    Joint(joint, type, id, parent, child_link, body_in_parent * Pose{pos, Quat::Identity()}, axis);
    parent = child_link;
    body_in_parent = {-pos, Quat::Identity()};
  }
  if (joints.empty() || parent != name) {  // welded to its parent, or offset from its last joint's anchor
    AddLink(std::move(link));
    JointSpec weld;
    weld.id = UniqueName(name + (joints.empty() ? "__fixed" : "__frame"), field + " fixed joint", &joint_names_, true);
    weld.type = JointType::kFixed;
    weld.parent_body = parent;
    weld.child_body = name;
    weld.origin = body_in_parent;
    description_.joints.push_back(std::move(weld));
  }
  for (const Child* body : bodies) Body(*body, name, body_global, depth + 1);
}

FileInertial Builder::ReadInertial(const Element& inertial, const Pose& frame) const {
  FileInertial file;
  file.field = inertial.field();
  file.origin = frame * FramePose(inertial, document_.compiler());
  const std::vector<double> mass = inertial.Numbers("mass", 1, 1);
  if (mass.empty()) ThrowInvalidArgument(inertial.field() + " has no mass attribute");
  file.mass = mass[0];
  const std::vector<double> diagonal = inertial.Numbers("diaginertia", 3, 3);
  const std::vector<double> full = inertial.Numbers("fullinertia", 6, 6);
  if (!diagonal.empty() && !full.empty()) {
    ThrowInvalidArgument(inertial.field() + ": both diaginertia and fullinertia given");
  }
  if (!diagonal.empty()) {
    file.inertia = Vec3(diagonal[0], diagonal[1], diagonal[2]).asDiagonal();
  } else if (!full.empty()) {  // ixx iyy izz ixy ixz iyz
    file.inertia << full[0], full[3], full[4], full[3], full[1], full[5], full[4], full[5], full[2];
  } else {
    ThrowInvalidArgument(inertial.field() + " has neither diaginertia nor fullinertia");
  }
  return file;
}

void Builder::Joint(const Element& joint, const std::string& type, const std::string& id, const std::string& parent,
                    const std::string& child, const Pose& origin, const Vec3& axis) {
  const std::string& field = joint.field();
  JointSpec spec;
  spec.id = id;
  spec.parent_body = parent;
  spec.child_body = child;
  spec.origin = origin;
  if (type == "free") {  // no limits, no axis: MuJoCo ignores them
    AppendFreeJoint(spec, 0, &description_, &inertials_);
    return;
  }
  const std::vector<double> range = joint.Numbers("range", 2, 2);
  const bool has_range = !range.empty() && !(range[0] == 0 && range[1] == 0);
  const bool automatic = document_.compiler().autolimits && has_range;  // limited="auto", MuJoCo's default
  const bool limited = joint.Bool("limited", automatic, automatic);
  if (limited && range.empty()) {
    ThrowInvalidArgument(field + " limited: " + Quoted(joint.String("limited")) + " but no range is given");
  }
  if (limited && range[0] > range[1]) {
    ThrowInvalidArgument(field + " range: lower " + Format(range[0]) + " is above upper " + Format(range[1]));
  }
  const double angle = document_.compiler().AngleScale();
  for (const char* attribute : {"ref", "springref"}) {
    if (type != "hinge" && type != "slide") break;
    const double value = joint.Number(attribute, 0);
    if (value != 0 && std::string(attribute) == "ref") {
      warnings_.Note(field + " ref", Format(value), "graspsim's position 0 is the pose the file draws: positions "
                                                    "and limits are MuJoCo's minus ref");
    } else if (value != 0) {
      warnings_.Note(field + " springref", Format(value), "ignored (graspsim models no joint springs)");
    }
  }
  const double ref = (type == "hinge" || type == "slide") ? joint.Number("ref", 0) : 0;
  if (type == "ball") {
    AppendBallJoint(spec, limited ? range[1] * angle : 0, &description_, &inertials_);
    return;
  }
  if (type == "fixed") {  // PyBullet's extension (pybullet_data's humanoid_fixed.xml); MuJoCo refuses it
    warnings_.Note(field + " type", "'fixed'", "a fixed joint (PyBullet's reading; MuJoCo has no fixed joints)");
    spec.type = JointType::kFixed;
    description_.joints.push_back(std::move(spec));
    return;
  }
  if (type != "hinge" && type != "slide") {
    ThrowInvalidArgument(field + " type: " + Quoted(type) + " is not free, ball, slide or hinge");
  }
  if (!(axis.norm() > 1e-10)) ThrowInvalidArgument(field + " axis: " + Quoted(joint.String("axis")) + " has zero length");
  spec.axis = axis.normalized();
  const double scale = type == "hinge" ? angle : 1.0;
  if (type == "hinge") {
    spec.type = limited ? JointType::kRevolute : JointType::kContinuous;
  } else {
    spec.type = JointType::kPrismatic;
  }
  if (limited) {
    spec.lower = range[0] * scale - ref * scale;
    spec.upper = range[1] * scale - ref * scale;
  } else if (type == "slide") {
    spec.lower = -kUnlimitedSlide;
    spec.upper = kUnlimitedSlide;
  }
  const std::vector<double> force = joint.Numbers("actuatorfrcrange", 2, 2);
  if (!force.empty() && joint.Bool("actuatorfrclimited", document_.compiler().autolimits, document_.compiler().autolimits)) {
    spec.effort_limit = std::max(std::abs(force[0]), std::abs(force[1]));
  }
  single_joints_[joint.xml().Attribute("name") != nullptr ? joint.xml().Attribute("name") : id] = id;
  description_.joints.push_back(std::move(spec));
}

}  // namespace
}  // namespace import::mjcf

ImportedRobot ImportMjcf(const std::string& text, const FileLookup& files, const ImportOptions& options,
                         const Limits& limits) {
  ImportedRobot robot;
  import::mjcf::Builder builder(text, files, options, limits, &robot.warnings);
  robot.description = builder.Build();
  return robot;
}

}  // namespace graspsim
