// URDF text → RobotDescription, with urdfdom for the standard elements and TinyXML for what urdfdom does not
// report well: XML syntax errors (line and column), the shape of the kinematic tree (urdfdom silently keeps the
// last of two parents and only says "not a valid tree" for a cycle), and graspsim's <tactile_array> elements.
// Unless strict, the document is repaired first (urdf_repairs.h) and the inertials resolved (loader_common.h).
#include <algorithm>
#include <charconv>
#include <cmath>
#include <map>
#include <memory>
#include <set>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include <console_bridge/console.h>
#include <tinyxml.h>
#include <urdf_model/model.h>
#include <urdf_parser/urdf_parser.h>

#include "core/error.h"
#include "core/format.h"
#include "core/log.h"
#include "core/validate.h"
#include "import/loader_common.h"
#include "import/robot_import.h"
#include "import/urdf_repairs.h"

namespace graspsim {
namespace {

using import::FileInertial;
using import::FileInertials;
using import::MeshFiles;
using import::Quoted;

// Mesh cells per texel edge: 16 gives 256 elements per texel, far finer than any foam's resolution.
constexpr unsigned kMaxSubdivision = 16;
// Far above any real tactile sensor; it only keeps a typo from allocating millions of texels downstream.
constexpr unsigned kMaxTexelsPerSide = 1024;

std::string Format(double value) { return FormatNumber(value); }

// urdfdom explains why it rejected a file only through console_bridge's log, and it even returns a model after
// logging some errors (a collision element it could not parse is dropped). This handler records the error
// messages of the parse running on the current thread and forwards every message to the server's structured
// log at debug level (the caller gets the errors in its status; console output would break the log's format).
class UrdfdomErrorCapture final : public console_bridge::OutputHandler {
 public:
  // Runs urdfdom; on return *errors holds every error it logged on this thread ("; "-separated).
  static urdf::ModelInterfaceSharedPtr Parse(const std::string& text, std::string* errors) {
    [[maybe_unused]] static UrdfdomErrorCapture* const installed = new UrdfdomErrorCapture();  // never freed
    thread_errors_ = errors;
    urdf::ModelInterfaceSharedPtr model;
    try {
      model = urdf::parseURDF(text);
    } catch (const std::exception& e) {  // urdfdom logs rather than throws, but nothing else may escape
      errors->append(errors->empty() ? e.what() : std::string("; ") + e.what());
    }
    thread_errors_ = nullptr;
    return model;
  }

  void log(const std::string& text, console_bridge::LogLevel level, const char* filename, int line) override {
    if (level >= console_bridge::CONSOLE_BRIDGE_LOG_ERROR && thread_errors_ != nullptr) {
      thread_errors_->append(thread_errors_->empty() ? text : "; " + text);
    }
    Log(LogLevel::kDebug, "urdfdom", {{"text", text}, {"source", std::string(filename) + ":" + std::to_string(line)}});
  }

 private:
  UrdfdomErrorCapture() { console_bridge::useOutputHandler(this); }

  static thread_local std::string* thread_errors_;
};

thread_local std::string* UrdfdomErrorCapture::thread_errors_ = nullptr;

Vec3 ToVec3(const urdf::Vector3& v) { return Vec3(v.x, v.y, v.z); }

Pose ToPose(const std::string& field, const urdf::Pose& pose) {
  Pose result{ToVec3(pose.position), Quat(pose.rotation.w, pose.rotation.x, pose.rotation.y, pose.rotation.z)};
  CheckPose(field, &result);
  return result;
}

// ---- The kinematic tree, read from the XML in document order -------------------------------------------------

struct JointEdge {
  std::string joint, parent, child;
};

struct TreeOrder {
  std::string root;
  std::vector<std::string> links;   // depth first from the root, children in document order
  std::vector<std::string> joints;  // the joint into each link after the root, same order
};

std::string RequiredAttribute(const TiXmlElement& element, const char* attribute, const std::string& owner) {
  const char* value = element.Attribute(attribute);
  if (value == nullptr || *value == '\0') {
    ThrowInvalidArgument("urdf: " + owner + " (line " + std::to_string(element.Row()) + ") has no " + attribute +
                         " attribute");
  }
  return value;
}

std::string LinkOf(const TiXmlElement& joint, const char* tag, const std::string& owner) {
  const TiXmlElement* element = joint.FirstChildElement(tag);
  if (element == nullptr) ThrowInvalidArgument("urdf: " + owner + " has no <" + tag + "> element");
  return RequiredAttribute(*element, "link", owner + " <" + tag + ">");
}

// One root, one parent per link, every link reachable from the root; anything else is rejected naming the links
// and joints involved.
TreeOrder CheckTree(const TiXmlElement& robot) {
  std::set<std::string> links, joint_names;
  for (const TiXmlElement* e = robot.FirstChildElement("link"); e != nullptr; e = e->NextSiblingElement("link")) {
    const std::string name = RequiredAttribute(*e, "name", "<link>");
    CheckName("urdf: link name", name);
    if (!links.insert(name).second) ThrowInvalidArgument("urdf: link " + Quoted(name) + " is defined twice");
  }
  if (links.empty()) ThrowInvalidArgument("urdf: the robot has no <link> element");
  std::vector<JointEdge> joints;
  for (const TiXmlElement* e = robot.FirstChildElement("joint"); e != nullptr; e = e->NextSiblingElement("joint")) {
    const std::string name = RequiredAttribute(*e, "name", "<joint>");
    CheckName("urdf: joint name", name);
    if (!joint_names.insert(name).second) ThrowInvalidArgument("urdf: joint " + Quoted(name) + " is defined twice");
    const std::string owner = "joint " + Quoted(name);
    joints.push_back({name, LinkOf(*e, "parent", owner), LinkOf(*e, "child", owner)});
  }

  std::map<std::string, const JointEdge*> parent_joint_of;  // link → the joint that moves it
  std::multimap<std::string, const JointEdge*> child_joints_of;
  for (const JointEdge& joint : joints) {
    for (const std::string* link : {&joint.parent, &joint.child}) {
      if (links.count(*link) == 0) {
        ThrowInvalidArgument("urdf: joint " + Quoted(joint.joint) + " names link " + Quoted(*link) +
                             ", which is not defined");
      }
    }
    if (const auto [it, inserted] = parent_joint_of.emplace(joint.child, &joint); !inserted) {
      ThrowInvalidArgument("urdf: link " + Quoted(joint.child) + " is the child of two joints, " +
                           Quoted(it->second->joint) + " and " + Quoted(joint.joint));
    }
    child_joints_of.emplace(joint.parent, &joint);
  }
  std::vector<std::string> roots;
  for (const std::string& link : links) {
    if (parent_joint_of.count(link) == 0) roots.push_back(link);
  }
  if (roots.size() > 1) {
    ThrowInvalidArgument("urdf: the robot has more than one root link (" + Quoted(roots[0]) + " and " +
                         Quoted(roots[1]) + "); every link but one must be the child of a joint");
  }

  TreeOrder order;
  if (!roots.empty()) order.root = roots[0];
  for (std::vector<std::string> pending = roots; !pending.empty();) {  // depth first, without recursion
    const std::string link = pending.back();
    pending.pop_back();
    order.links.push_back(link);
    if (link != order.root) order.joints.push_back(parent_joint_of.at(link)->joint);
    const auto [first, last] = child_joints_of.equal_range(link);
    for (auto it = last; it != first;) pending.push_back((--it)->second->child);
  }
  if (order.links.size() < links.size()) {
    // With one parent per link, walking up from a link the root does not reach must close a loop.
    const std::set<std::string> reached(order.links.begin(), order.links.end());
    std::string link = *std::find_if(links.begin(), links.end(), [&](const auto& l) { return !reached.count(l); });
    for (std::set<std::string> seen; seen.insert(link).second;) link = parent_joint_of.at(link)->parent;
    std::string cycle;
    for (std::string at = link; cycle.empty() || at != link; at = parent_joint_of.at(at)->parent) {
      cycle += (cycle.empty() ? "" : ", ") + Quoted(parent_joint_of.at(at)->joint);
    }
    ThrowInvalidArgument("urdf: the joints " + cycle + " form a cycle; a URDF must be a tree");
  }
  return order;
}

// ---- Links --------------------------------------------------------------------------------------------------

MeshFiles::Request MeshRequest(const std::string& link, const urdf::Mesh& mesh) {
  return {"urdf: link " + Quoted(link) + " mesh " + Quoted(mesh.filename), import::MeshPathCandidates(mesh.filename),
          ToVec3(mesh.scale)};
}

// Every collision mesh of the robot, for MeshFiles::Prefetch.
std::vector<MeshFiles::Request> MeshRequests(const urdf::ModelInterface& model, const std::vector<std::string>& links) {
  std::vector<MeshFiles::Request> requests;
  for (const std::string& link : links) {
    const urdf::LinkConstSharedPtr parsed = model.getLink(link);
    if (parsed == nullptr) continue;
    for (const urdf::CollisionSharedPtr& collision : parsed->collision_array) {
      if (collision != nullptr && collision->geometry != nullptr && collision->geometry->type == urdf::Geometry::MESH) {
        requests.push_back(MeshRequest(link, static_cast<const urdf::Mesh&>(*collision->geometry)));
      }
    }
  }
  return requests;
}

// The link's collision geometry; a mesh file that was not uploaded is left out and remembered by `meshes`.
std::vector<Geometry> ConvertCollision(const std::string& link, size_t index, const urdf::Collision& collision,
                                       MeshFiles* meshes) {
  const std::string field = "urdf: link " + Quoted(link) + " collision " + std::to_string(index);
  Geometry geometry;
  geometry.origin = ToPose(field + " origin", collision.origin);
  if (collision.geometry == nullptr) ThrowInvalidArgument(field + " has no geometry");
  switch (collision.geometry->type) {
    case urdf::Geometry::BOX: {
      geometry.kind = Geometry::Kind::kBox;
      geometry.box_size = ToVec3(static_cast<const urdf::Box&>(*collision.geometry).dim);
      for (int axis = 0; axis < 3; ++axis) CheckPositive(field + " box size", geometry.box_size[axis]);
      break;
    }
    case urdf::Geometry::SPHERE:
      geometry.kind = Geometry::Kind::kSphere;
      geometry.radius = static_cast<const urdf::Sphere&>(*collision.geometry).radius;
      CheckPositive(field + " sphere radius", geometry.radius);
      break;
    case urdf::Geometry::CYLINDER: {
      const auto& cylinder = static_cast<const urdf::Cylinder&>(*collision.geometry);
      geometry.kind = Geometry::Kind::kCylinder;
      geometry.radius = cylinder.radius;
      geometry.length = cylinder.length;
      CheckPositive(field + " cylinder radius", geometry.radius);
      CheckPositive(field + " cylinder length", geometry.length);
      break;
    }
    case urdf::Geometry::MESH: {
      const auto& mesh = static_cast<const urdf::Mesh&>(*collision.geometry);
      const MeshFiles::Request request = MeshRequest(link, mesh);
      geometry.kind = Geometry::Kind::kMesh;
      if (!meshes->Load(request.field, mesh.filename, request.candidates, request.scale, &geometry)) {
        return {};
      }
      break;
    }
  }
  return {geometry};
}

FileInertial ConvertInertial(const urdf::Link& link) {
  const urdf::Inertial& in = *link.inertial;
  FileInertial file;
  file.field = "urdf: link " + Quoted(link.name) + " inertial";
  file.mass = in.mass;
  file.origin = ToPose(file.field + " origin", in.origin);
  file.inertia << in.ixx, in.ixy, in.ixz, in.ixy, in.iyy, in.iyz, in.ixz, in.iyz, in.izz;
  return file;
}

BodySpec ConvertLink(const urdf::Link& link, const std::vector<Geometry>& extra, MeshFiles* meshes,
                     FileInertials* inertials) {
  BodySpec body;
  body.id = link.name;
  body.motion = BodyMotion::kArticulated;
  std::vector<urdf::CollisionSharedPtr> collisions = link.collision_array;
  if (collisions.empty() && link.collision != nullptr) collisions.push_back(link.collision);
  for (size_t i = 0; i < collisions.size(); ++i) {
    for (Geometry& g : ConvertCollision(link.name, i, *collisions[i], meshes)) body.collision.push_back(std::move(g));
  }
  body.collision.insert(body.collision.end(), extra.begin(), extra.end());
  if (link.inertial != nullptr) (*inertials)[link.name] = ConvertInertial(link);
  return body;
}

// ---- Joints -------------------------------------------------------------------------------------------------

JointSpec ConvertJoint(const urdf::Joint& joint, const urdf::ModelInterface& model) {
  const std::string field = "urdf: joint " + Quoted(joint.name);
  JointSpec spec;
  spec.id = joint.name;
  spec.parent_body = joint.parent_link_name;
  spec.child_body = joint.child_link_name;
  spec.origin = ToPose(field + " origin", joint.parent_to_joint_origin_transform);
  switch (joint.type) {
    case urdf::Joint::REVOLUTE: spec.type = JointType::kRevolute; break;
    case urdf::Joint::CONTINUOUS: spec.type = JointType::kContinuous; break;
    case urdf::Joint::PRISMATIC: spec.type = JointType::kPrismatic; break;
    case urdf::Joint::FIXED: spec.type = JointType::kFixed; break;
    default:
      ThrowInvalidArgument(field + " has type " +
                           (joint.type == urdf::Joint::FLOATING ? std::string("floating")
                            : joint.type == urdf::Joint::PLANAR ? std::string("planar")
                                                                 : std::string("unknown")) +
                           "; supported: revolute, continuous, prismatic, fixed");
  }
  if (spec.type == JointType::kFixed) return spec;

  const Vec3 axis = ToVec3(joint.axis);
  CheckFinite(field + " axis", axis);
  if (axis.norm() < 1e-9) {
    ThrowInvalidArgument(field + " axis (" + Format(axis.x()) + ", " + Format(axis.y()) + ", " + Format(axis.z()) +
                         ") has zero length");
  }
  spec.axis = axis.normalized();

  const bool needs_limits = spec.type == JointType::kRevolute || spec.type == JointType::kPrismatic;
  if (needs_limits && joint.limits == nullptr) ThrowInvalidArgument(field + " has no <limit>");
  if (joint.limits != nullptr) {
    CheckNonNegative(field + " velocity limit", joint.limits->velocity);
    CheckNonNegative(field + " effort limit", joint.limits->effort);
    spec.velocity_limit = joint.limits->velocity;
    spec.effort_limit = joint.limits->effort;
    if (needs_limits) {
      CheckFinite(field + " lower limit", joint.limits->lower);
      CheckFinite(field + " upper limit", joint.limits->upper);
      if (joint.limits->lower > joint.limits->upper) {
        ThrowInvalidArgument(field + " lower limit " + Format(joint.limits->lower) + " is above its upper limit " +
                             Format(joint.limits->upper));
      }
      spec.lower = joint.limits->lower;
      spec.upper = joint.limits->upper;
    }
  }

  if (joint.mimic != nullptr) {
    const std::string& leader_name = joint.mimic->joint_name;
    const urdf::JointConstSharedPtr leader = model.getJoint(leader_name);
    if (leader == nullptr || leader_name == joint.name) {
      ThrowInvalidArgument(field + " mimics joint " + Quoted(leader_name) + ", which " +
                           (leader == nullptr ? "does not exist" : "is itself"));
    }
    // A leader that mimics another joint would need chains (or cycles) resolved downstream.
    if (leader->mimic != nullptr) {
      ThrowInvalidArgument(field + " mimics joint " + Quoted(leader_name) + ", which itself mimics " +
                           Quoted(leader->mimic->joint_name) + "; mimic the leader directly");
    }
    CheckFinite(field + " mimic multiplier", joint.mimic->multiplier);
    CheckFinite(field + " mimic offset", joint.mimic->offset);
    spec.mimic = MimicSpec{leader_name, joint.mimic->multiplier, joint.mimic->offset};
  }
  return spec;
}

// ---- graspsim's <tactile_array> extension --------------------------------------------------------------------

// Parses exactly `count` whitespace-separated numbers. NaN and Inf parse, so CheckFinite can name them.
std::vector<double> ParseNumbers(const std::string& field, const std::string& text, size_t count) {
  std::vector<double> numbers;
  std::istringstream words(text);
  for (std::string word; words >> word;) {
    double value = 0;
    const auto [end, error] = std::from_chars(word.data(), word.data() + word.size(), value);
    if (error != std::errc() || end != word.data() + word.size()) {
      ThrowInvalidArgument(field + ": " + Quoted(word) + " is not a number");
    }
    CheckFinite(field, value);
    numbers.push_back(value);
  }
  if (numbers.size() != count) {
    ThrowInvalidArgument(field + ": " + Quoted(text) + " is not " + std::to_string(count) + " number(s)");
  }
  return numbers;
}

unsigned ParseTexelCount(const std::string& field, const std::string& text) {
  unsigned value = 0;
  const auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (error != std::errc() || end != text.data() + text.size() || value == 0 || value > kMaxTexelsPerSide) {
    ThrowInvalidArgument(field + ": " + Quoted(text) + " is not an integer in 1.." +
                         std::to_string(kMaxTexelsPerSide));
  }
  return value;
}

std::vector<TactileArraySpec> ParseTactileArrays(const TiXmlElement& robot, const std::set<std::string>& links) {
  std::vector<TactileArraySpec> arrays;
  std::set<std::string> names;
  for (const TiXmlElement* e = robot.FirstChildElement("tactile_array"); e != nullptr;
       e = e->NextSiblingElement("tactile_array")) {
    TactileArraySpec spec;
    spec.id = RequiredAttribute(*e, "name", "<tactile_array>");
    CheckName("urdf: tactile_array name", spec.id);
    const std::string field = "urdf: tactile_array " + Quoted(spec.id);
    if (!names.insert(spec.id).second) ThrowInvalidArgument(field + " is defined twice");
    spec.body_id = RequiredAttribute(*e, "link", field);
    if (links.count(spec.body_id) == 0) {
      ThrowInvalidArgument(field + " is on link " + Quoted(spec.body_id) + ", which does not exist");
    }
    spec.rows = ParseTexelCount(field + " rows", RequiredAttribute(*e, "rows", field));
    spec.cols = ParseTexelCount(field + " cols", RequiredAttribute(*e, "cols", field));
    spec.pitch = ParseNumbers(field + " pitch (m)", RequiredAttribute(*e, "pitch", field), 1)[0];
    CheckPositive(field + " pitch (m)", spec.pitch);
    spec.thickness = ParseNumbers(field + " thickness (m)", RequiredAttribute(*e, "thickness", field), 1)[0];
    CheckPositive(field + " thickness (m)", spec.thickness);
    // The sensing mesh (world/model.h): optional, a flat grid with one element per texel by default.
    if (const char* text = e->Attribute("subdivision"); text != nullptr) {
      spec.subdivision = ParseTexelCount(field + " subdivision", text);
      if (spec.subdivision > kMaxSubdivision) {
        ThrowInvalidArgument(field + " subdivision: " + Quoted(text) + " is above " + std::to_string(kMaxSubdivision));
      }
    }
    if (const char* text = e->Attribute("elements"); text != nullptr) {
      const std::string placement = text;
      if (placement == "vertices") {
        spec.placement = PadElementPlacement::kVertices;
      } else if (placement == "face_centres") {
        spec.placement = PadElementPlacement::kFaceCentres;
      } else {
        ThrowInvalidArgument(field + " elements: " + Quoted(placement) + " is not \"vertices\" or \"face_centres\"");
      }
    }
    if (const char* text = e->Attribute("bend_radius"); text != nullptr) {
      const std::vector<double> radii = ParseNumbers(field + " bend_radius (m)", text, 2);
      const double widths[2] = {spec.cols * spec.pitch, spec.rows * spec.pitch};
      for (int k = 0; k < 2; ++k) {
        // 0 = flat; otherwise at most a quarter turn each way from the centre.
        if (radii[k] != 0 && !(radii[k] >= widths[k] / M_PI)) {
          ThrowInvalidArgument(field + " bend_radius (m): " + FormatNumber(radii[k]) + " along " + "xy"[k] +
                               " must be 0 (flat) or at least the width / pi = " + FormatNumber(widths[k] / M_PI));
        }
      }
      spec.bend_radius_x = radii[0];
      spec.bend_radius_y = radii[1];
    }
    if (const TiXmlElement* origin = e->FirstChildElement("origin"); origin != nullptr) {
      const auto vector = [&](const char* attribute) {
        const char* text = origin->Attribute(attribute);
        if (text == nullptr) return Vec3::Zero().eval();
        const std::vector<double> v = ParseNumbers(field + " origin " + attribute, text, 3);
        return Vec3(v[0], v[1], v[2]);
      };
      const Vec3 rpy = vector("rpy");
      spec.origin = {vector("xyz"), QuatFromRpy(rpy.x(), rpy.y(), rpy.z())};
    }
    arrays.push_back(std::move(spec));
  }
  return arrays;
}

}  // namespace

ImportedRobot ImportUrdf(const std::string& urdf_text, const FileLookup& files, const ImportOptions& options,
                         const Limits& limits) {
  ImportedRobot imported;
  std::vector<ImportWarning>& warnings = imported.warnings;
  // Files saved by some tools end in NUL bytes (pybullet_data's humanoid.urdf); TinyXML must not see them.
  std::string text = urdf_text;
  if (!options.strict && !text.empty() && text.back() == '\0') {
    const size_t end = text.find_last_not_of('\0') + 1;
    warnings.push_back({"urdf: the text's last bytes", std::to_string(text.size() - end) + " NUL byte(s)", "ignored"});
    text.resize(end);
  }
  import::CheckXmlText("urdf", text);
  TiXmlDocument document;
  document.Parse(text.c_str());
  if (document.Error()) {
    // TinyXML reports row 0 when it cannot place the error (e.g. text that is not XML at all).
    const std::string where = document.ErrorRow() > 0 ? " at line " + std::to_string(document.ErrorRow()) +
                                                            " column " + std::to_string(document.ErrorCol())
                                                      : "";
    ThrowInvalidArgument("urdf: XML error" + where + ": " + document.ErrorDesc());
  }
  TiXmlElement* robot = document.RootElement();
  if (robot == nullptr || robot->ValueStr() != "robot") {
    ThrowInvalidArgument("urdf: the root element is not <robot>");
  }
  const import::UrdfRepairs repairs = options.strict ? import::UrdfRepairs{} : import::RepairUrdfDocument(robot, &warnings);
  const TreeOrder order = CheckTree(*robot);

  std::string repaired_text;
  if (repairs.document_changed) {
    TiXmlPrinter printer;
    document.Accept(&printer);
    repaired_text = printer.Str();
  }
  std::string urdfdom_errors;
  const urdf::ModelInterfaceSharedPtr model =
      UrdfdomErrorCapture::Parse(repaired_text.empty() ? text : repaired_text, &urdfdom_errors);
  if (model == nullptr || !urdfdom_errors.empty()) {
    ThrowInvalidArgument("urdf: " + (urdfdom_errors.empty() ? std::string("urdfdom rejected the robot description")
                                                            : urdfdom_errors));
  }

  RobotDescription& description = imported.description;
  description.name = model->getName();
  description.root_link = order.root;
  MeshFiles meshes(files, limits);
  FileInertials inertials;
  // urdfdom and CheckTree read the same elements, so a name missing from urdfdom's model is a bug, not bad input.
  const auto missing = [](const std::string& what) {
    return Error(ErrorCode::kInternal, "urdf: urdfdom's model has no " + what);
  };
  static const std::vector<Geometry> kNone;
  meshes.Prefetch(MeshRequests(*model, order.links));
  for (const std::string& link : order.links) {
    const urdf::LinkConstSharedPtr parsed = model->getLink(link);
    if (parsed == nullptr) throw missing("link " + Quoted(link));
    const auto extra = repairs.extra_collision.find(link);
    description.links.push_back(
        ConvertLink(*parsed, extra == repairs.extra_collision.end() ? kNone : extra->second, &meshes, &inertials));
  }
  meshes.ThrowIfMissing("urdf");
  for (const std::string& joint : order.joints) {
    const urdf::JointConstSharedPtr parsed = model->getJoint(joint);
    if (parsed == nullptr) throw missing("joint " + Quoted(joint));
    JointSpec spec = ConvertJoint(*parsed, *model);
    if (const auto chain = repairs.chain_joints.find(joint); chain != repairs.chain_joints.end()) {
      // A ball joint's <limit upper> bounds each angle, as PyBullet reads it; a floating joint is unbounded.
      const double limit = parsed->limits != nullptr && parsed->limits->upper > 0 ? parsed->limits->upper : 0;
      if (chain->second == "ball") {
        import::AppendBallJoint(spec, limit, &description, &inertials);
      } else {
        import::AppendFreeJoint(spec, 0, &description, &inertials);
      }
      continue;
    }
    description.joints.push_back(std::move(spec));
  }
  import::ResolveInertials("urdf", inertials, options, &description, &warnings);
  description.tactile_arrays =
      ParseTactileArrays(*robot, std::set<std::string>(order.links.begin(), order.links.end()));
  return imported;
}

RobotDescription LoadUrdf(const std::string& urdf_text, const FileLookup& files, const Limits& limits) {
  ImportOptions strict;
  strict.strict = true;
  return ImportUrdf(urdf_text, files, strict, limits).description;
}

}  // namespace graspsim
