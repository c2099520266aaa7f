// One SDF model as a graspsim robot (sdf_internal.h ConvertSdfModel): nested models flattened, poses resolved by
// libsdformat (sdf::SemanticPose), joints in graspsim's convention (the child body frame is the joint frame), the
// tree rooted at the link the world holds, the links' inertials resolved by ResolveInertials.
#include <algorithm>
#include <cmath>
#include <map>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "core/error.h"
#include "core/format.h"
#include "import/sdf_internal.h"
#include "import/primitive_shapes.h"

namespace graspsim::import {
namespace {

// A joint's parent when it is the world (not a link named "world", which PyBullet's files define).
const std::string kWorld = "\x01world";

struct FlatLink {
  std::string name;       // graspsim's (sanitised, scopes flattened)
  std::string sdf_name;   // as the file scopes it: "arm::link1"
  const sdf::Link* link = nullptr;
  Pose pose;              // link frame in the top model's frame
};

struct FlatJoint {
  std::string name, sdf_name;
  const sdf::Joint* joint = nullptr;
  std::string parent, child;  // graspsim link names; parent kWorld for the world
  Pose pose;                  // joint frame in the top model's frame
};

class SdfConverter {
 public:
  SdfConverter(const FileLookup& files, const ImportOptions& options, const Limits& limits)
      : options_(options), meshes_(files, limits), repairs_(options.strict, &result_.warnings) {}

  ImportedRobot Convert(const sdf::Model& model, const Pose& model_in_world);

 private:
  void Warn(const std::string& element, const std::string& value, const std::string& action) {
    repairs_.Warn(element, value, action);
  }
  BodySpec ConvertLink(const FlatLink& link) {
    return ConvertSdfLink(*link.link, link.name, model_field_ + " link " + Quoted(link.sdf_name), &meshes_, &repairs_);
  }
  std::string UniqueName(const std::string& sdf_name, const std::string& what, std::set<std::string>* used);
  // A name for a link or joint graspsim adds (base + suffix), valid and unused, entered in *used.
  static std::string Added(const std::string& base, const std::string& suffix, std::set<std::string>* used);
  void Flatten(const sdf::Model& model, const std::string& prefix, const Pose& in_top);
  void AddChainLink(const std::string& name);
  void EmitJoint(const FlatJoint& joint, const Pose& parent_pose, const FlatLink& child);

  const ImportOptions& options_;
  MeshFiles meshes_;
  std::string model_field_;  // "sdf: model 'm'"
  bool static_ = false;
  std::vector<FlatLink> links_;
  std::vector<FlatJoint> joints_;
  std::set<std::string> link_names_, joint_names_;
  FileInertials inertials_;
  ImportedRobot result_;  // before repairs_, which holds its warnings
  SdfRepairs repairs_;
};

std::string SdfConverter::UniqueName(const std::string& sdf_name, const std::string& what,
                                     std::set<std::string>* used) {
  bool changed = false;
  std::string name = SanitiseName(sdf_name, &changed);
  if (used->count(name) > 0) {
    const std::string base = name.substr(0, 58);
    for (int k = 2; used->count(name) > 0; ++k) name = base + "_" + std::to_string(k);
    changed = true;
  }
  if (changed) {
    Warn(model_field_ + " " + what + " name", Quoted(sdf_name), "renamed " + Quoted(name) + " (graspsim names are " +
         "1..64 characters of letters, digits, '_', '-', '.', unique)");
  }
  used->insert(name);
  return name;
}

std::string SdfConverter::Added(const std::string& base, const std::string& suffix, std::set<std::string>* used) {
  const std::string stem = base.substr(0, 60 - suffix.size()) + suffix;
  std::string name = stem;
  for (int k = 2; used->count(name) > 0; ++k) name = stem + "_" + std::to_string(k);
  used->insert(name);
  return name;
}

void SdfConverter::Flatten(const sdf::Model& model, const std::string& prefix, const Pose& in_top) {
  const std::string scope = prefix.empty() ? model_field_ : model_field_ + " nested model " + Quoted(prefix);
  for (uint64_t i = 0; i < model.LinkCount(); ++i) {
    const sdf::Link* link = model.LinkByIndex(i);
    FlatLink flat;
    flat.sdf_name = prefix + link->Name();
    flat.name = UniqueName(flat.sdf_name, "link", &link_names_);
    flat.link = link;
    ignition::math::Pose3d pose;
    const sdf::Errors errors = link->SemanticPose().Resolve(pose, "__model__");
    if (!errors.empty()) {
      ThrowInvalidArgument(scope + " link " + Quoted(link->Name()) + " pose: " + Describe(errors[0]));
    }
    flat.pose = in_top * ToPose(pose, scope + " link " + Quoted(link->Name()) + " pose");
    links_.push_back(flat);
  }
  for (uint64_t i = 0; i < model.JointCount(); ++i) {
    const sdf::Joint* joint = model.JointByIndex(i);
    const std::string field = scope + " joint " + Quoted(joint->Name());
    FlatJoint flat;
    flat.sdf_name = prefix + joint->Name();
    flat.name = UniqueName(flat.sdf_name, "joint", &joint_names_);
    flat.joint = joint;
    std::string parent, child;
    sdf::Errors errors = joint->ResolveParentLink(parent);
    if (errors.empty()) errors = joint->ResolveChildLink(child);
    if (!errors.empty()) ThrowInvalidArgument(field + " parent/child: " + Describe(errors[0]));
    flat.parent = (parent == "world" && !model.LinkNameExists("world")) ? kWorld : prefix + parent;
    flat.child = prefix + child;
    ignition::math::Pose3d pose;
    errors = joint->SemanticPose().Resolve(pose, "__model__");
    if (!errors.empty()) ThrowInvalidArgument(field + " pose: " + Describe(errors[0]));
    flat.pose = in_top * ToPose(pose, field + " pose");
    joints_.push_back(flat);
  }
  for (uint64_t i = 0; i < model.ModelCount(); ++i) {
    const sdf::Model* nested = model.ModelByIndex(i);
    ignition::math::Pose3d pose;
    const sdf::Errors errors = nested->SemanticPose().Resolve(pose, "__model__");
    const std::string field = scope + " nested model " + Quoted(nested->Name()) + " pose";
    if (!errors.empty()) ThrowInvalidArgument(field + ": " + Describe(errors[0]));
    Flatten(*nested, prefix + nested->Name() + "::", in_top * ToPose(pose, field));
  }
}

void SdfConverter::AddChainLink(const std::string& name) {
  BodySpec body;
  body.id = name;
  body.motion = BodyMotion::kArticulated;
  result_.description.links.push_back(body);
  FileInertial massless;
  massless.field = model_field_ + " link " + Quoted(name);
  massless.massless = true;
  inertials_[name] = massless;
}

// The joint into `child`, at its zero position. graspsim's child body frame is the joint frame; an SDF joint frame
// that is not the child link's frame gets a massless link of its own, fixed to the child link at their offset, so
// the forward kinematics of every SDF link frame is exact.
void SdfConverter::EmitJoint(const FlatJoint& joint, const Pose& parent_pose, const FlatLink& child) {
  RobotDescription& d = result_.description;
  const std::string field = model_field_ + " joint " + Quoted(joint.sdf_name);
  sdf::JointType type = joint.joint->Type();
  if (static_ && type != sdf::JointType::FIXED) type = sdf::JointType::FIXED;  // warned in Convert
  JointSpec spec;
  spec.id = joint.name;
  spec.parent_body = joint.parent;
  spec.origin = parent_pose.Inverse() * joint.pose;
  if (type == sdf::JointType::FIXED) {
    spec.type = JointType::kFixed;
    spec.child_body = child.name;
    spec.origin = parent_pose.Inverse() * child.pose;
    d.links.push_back(ConvertLink(child));
    d.joints.push_back(spec);
    return;
  }
  const Pose offset = joint.pose.Inverse() * child.pose;  // the child link frame in the joint frame
  const bool same_frame =
      offset.position.norm() < 1e-12 && offset.orientation.angularDistance(Quat::Identity()) < 1e-12;
  const std::string target = same_frame ? child.name : Added(child.name, "__joint_frame", &link_names_);
  spec.child_body = target;
  const auto axis_of = [&](unsigned index) {
    const sdf::JointAxis* axis = joint.joint->Axis(index);
    if (axis == nullptr) ThrowInvalidArgument(field + " has no <axis" + (index ? "2" : "") + ">");
    ignition::math::Vector3d xyz;
    const sdf::Errors errors = axis->ResolveXyz(xyz, "");
    if (!errors.empty()) ThrowInvalidArgument(field + " axis: " + Describe(errors[0]));
    const Vec3 v = ToVec3(xyz);
    CheckFinite(field + " axis xyz", v);
    if (v.norm() < 1e-9) ThrowInvalidArgument(field + " axis xyz has zero length");
    return axis;
  };
  const auto set_axis = [&](unsigned index, JointSpec* s, bool revolute) {
    const sdf::JointAxis* axis = axis_of(index);
    ignition::math::Vector3d xyz;
    axis->ResolveXyz(xyz, "");
    s->axis = ToVec3(xyz).normalized();
    const double lower = axis->Lower(), upper = axis->Upper();
    const std::string limit_field = field + " axis" + (index ? "2" : "") + " limit";
    const bool unlimited = std::isinf(lower) || std::isinf(upper) || lower <= -1e16 || upper >= 1e16;
    if (revolute && unlimited) {
      s->type = JointType::kContinuous;
    } else {
      if (unlimited) ThrowInvalidArgument(limit_field + ": a prismatic joint needs finite <lower> and <upper>");
      CheckFinite(limit_field + " lower", lower);
      CheckFinite(limit_field + " upper", upper);
      if (lower > upper) {
        ThrowInvalidArgument(limit_field + " lower " + FormatNumber(lower) + " is above upper " + FormatNumber(upper));
      }
      s->type = revolute ? JointType::kRevolute : JointType::kPrismatic;
      s->lower = lower;
      s->upper = upper;
    }
    if (std::isfinite(axis->Effort()) && axis->Effort() > 0) s->effort_limit = axis->Effort();
    if (std::isfinite(axis->MaxVelocity()) && axis->MaxVelocity() > 0) s->velocity_limit = axis->MaxVelocity();
  };
  switch (type) {
    case sdf::JointType::REVOLUTE:
    case sdf::JointType::CONTINUOUS:
    case sdf::JointType::PRISMATIC:
      set_axis(0, &spec, type != sdf::JointType::PRISMATIC);
      if (type == sdf::JointType::CONTINUOUS) spec.type = JointType::kContinuous;
      if (!same_frame) AddChainLink(target);
      d.joints.push_back(spec);
      break;
    case sdf::JointType::BALL:
      if (same_frame) {
        d.links.push_back(ConvertLink(child));
      } else {
        AddChainLink(target);
      }
      AppendBallJoint(spec, 0, &d, &inertials_);
      if (same_frame) return;
      break;
    case sdf::JointType::UNIVERSAL:
    case sdf::JointType::REVOLUTE2: {
      const std::string middle = Added(child.name, "__axis1", &link_names_);
      JointSpec first = spec, second = spec;
      first.id = Added(joint.name, "__axis1", &joint_names_);
      first.child_body = middle;
      set_axis(0, &first, true);
      second.id = Added(joint.name, "__axis2", &joint_names_);
      second.parent_body = middle;
      second.origin = Pose{};
      set_axis(1, &second, true);
      AddChainLink(middle);
      d.joints.push_back(first);
      if (!same_frame) AddChainLink(target);
      d.joints.push_back(second);
      break;
    }
    default:
      ThrowInvalidArgument(field + " has type " +
                           (type == sdf::JointType::SCREW     ? std::string("screw")
                            : type == sdf::JointType::GEARBOX ? std::string("gearbox")
                                                              : std::string("invalid")) +
                           "; supported: revolute, continuous, prismatic, fixed, ball, universal, revolute2");
  }
  d.links.push_back(ConvertLink(child));
  if (!same_frame) {
    JointSpec fixed;
    fixed.id = Added(joint.name, "__frame", &joint_names_);
    fixed.type = JointType::kFixed;
    fixed.parent_body = target;
    fixed.child_body = child.name;
    fixed.origin = offset;
    d.joints.push_back(fixed);
  }
}

ImportedRobot SdfConverter::Convert(const sdf::Model& model, const Pose& model_in_world) {
  model_field_ = "sdf: model " + Quoted(model.Name());
  bool renamed = false;
  result_.description.name = SanitiseName(model.Name(), &renamed);
  static_ = model.Static();
  Flatten(model, "", Pose{});
  if (links_.empty()) ThrowInvalidArgument(model_field_ + " has no <link>");
  std::vector<MeshFiles::Request> mesh_requests;  // parsed side by side before the links need them
  for (const FlatLink& link : links_) {
    for (uint64_t c = 0; c < link.link->CollisionCount(); ++c) {
      const sdf::Geometry* geometry = link.link->CollisionByIndex(c)->Geom();
      if (geometry == nullptr || geometry->Type() != sdf::GeometryType::MESH || geometry->MeshShape() == nullptr) continue;
      const sdf::Mesh& mesh = *geometry->MeshShape();
      const auto& scale = mesh.Scale();
      mesh_requests.push_back({model_field_ + " link " + Quoted(link.sdf_name) + " mesh " + Quoted(mesh.Uri()),
                               MeshPathCandidates(mesh.Uri()), Vec3(scale.X(), scale.Y(), scale.Z())});
    }
  }
  meshes_.Prefetch(mesh_requests);

  std::map<std::string, size_t> link_index;
  std::map<std::string, std::string> by_sdf_name;  // "a::b" → graspsim's name
  for (size_t i = 0; i < links_.size(); ++i) {
    link_index[links_[i].name] = i;
    by_sdf_name[links_[i].sdf_name] = links_[i].name;
  }
  // The tree: one parent joint per link; a joint from the world welds the model (fixed) or moves it relative to a
  // massless root link at the world frame.
  std::map<std::string, size_t> parent_joint;
  std::multimap<std::string, size_t> child_joints;
  const FlatJoint* world_joint = nullptr;
  for (size_t i = 0; i < joints_.size(); ++i) {
    FlatJoint& joint = joints_[i];
    const std::string field = model_field_ + " joint " + Quoted(joint.sdf_name);
    for (std::string* end : {&joint.parent, &joint.child}) {
      if (end == &joint.parent && *end == kWorld) continue;
      const auto it = by_sdf_name.find(*end);
      if (it == by_sdf_name.end()) {
        ThrowInvalidArgument(field + " names link " + Quoted(*end) + ", which is not defined");
      }
      *end = it->second;
    }
    if (joint.parent == kWorld) {
      if (world_joint != nullptr) {
        ThrowInvalidArgument(field + " and joint " + Quoted(world_joint->sdf_name) +
                             " both attach the model to the world; a robot has one base");
      }
      world_joint = &joint;
    }
    if (const auto [it, inserted] = parent_joint.emplace(joint.child, i); !inserted) {
      ThrowInvalidArgument(model_field_ + " link " + Quoted(links_[link_index.at(joint.child)].sdf_name) +
                           " is the child of two joints, " + Quoted(joints_[it->second].sdf_name) + " and " +
                           Quoted(joint.sdf_name));
    }
    child_joints.emplace(joint.parent, i);
  }

  std::string root;
  Pose root_pose;
  bool synthetic_root = false;  // a massless link at the world frame, for a model moving relative to the world
  RobotDescription& d = result_.description;
  if (world_joint != nullptr && world_joint->joint->Type() != sdf::JointType::FIXED && !static_) {
    root = Added("world", "", &link_names_);  // "world" is reserved for links in SDF, so normally free
    root_pose = model_in_world.Inverse();
    synthetic_root = true;
    const size_t index = static_cast<size_t>(world_joint - joints_.data());
    joints_[index].parent = root;
    child_joints.emplace(root, index);
  } else if (world_joint != nullptr) {
    root = world_joint->child;  // welded at the robot's base pose
    parent_joint.erase(root);
  } else {
    // The canonical link may be a nested model's ("inner::base"): its name relative to this model.
    const auto [canonical, canonical_name] = model.CanonicalLinkAndRelativeName();
    root = links_[0].name;
    if (canonical != nullptr && by_sdf_name.count(canonical_name) > 0) root = by_sdf_name.at(canonical_name);
    if (parent_joint.count(root) > 0) {
      for (const FlatLink& link : links_) {
        if (parent_joint.count(link.name) == 0) {
          root = link.name;
          break;
        }
      }
    }
    // PyBullet's grippers define a link named "world" (reserved in SDF) and joint their base to it.
    if (!static_ && root != "world") {
      Warn(model_field_, "(not static, no joint to the world)",
           "its link " + Quoted(root) + " is fixed at the robot's base pose: graspsim robots have fixed bases");
    }
  }
  if (static_) {
    size_t moving = 0;
    for (const FlatJoint& joint : joints_) moving += joint.joint->Type() != sdf::JointType::FIXED;
    if (moving > 0) {
      Warn(model_field_ + " static", "true", "its " + std::to_string(moving) + " moving joint(s) are held fixed");
    }
  }
  if (!synthetic_root) root_pose = links_[link_index.at(root)].pose;
  d.root_link = root;
  // Links no joint reaches: fixed to the root where the file places them.
  for (const FlatLink& link : links_) {
    if (link.name != root && parent_joint.count(link.name) == 0) {
      Warn(model_field_ + " link " + Quoted(link.sdf_name), "(no joint)",
           "fixed to the root link " + Quoted(root) + " where the file places it (graspsim robots are one tree)");
      FlatJoint weld;
      weld.name = Added(link.name, "__fixed", &joint_names_);
      weld.parent = root;
      weld.child = link.name;
      weld.pose = link.pose;
      joints_.push_back(weld);  // joint pointer left null: EmitJoint is not used for welds
      parent_joint[link.name] = joints_.size() - 1;
      child_joints.emplace(root, joints_.size() - 1);
    }
  }
  // Depth first from the root, children in document order.
  std::map<std::string, Pose> placed;  // graspsim body frames in the model frame (chain links excluded)
  if (synthetic_root) {
    AddChainLink(root);
  } else {
    d.links.push_back(ConvertLink(links_[link_index.at(root)]));
  }
  placed[root] = root_pose;
  size_t reached = synthetic_root ? 0 : 1;
  for (std::vector<std::string> pending{root}; !pending.empty();) {
    const std::string link = pending.back();
    pending.pop_back();
    const auto [first, last] = child_joints.equal_range(link);
    std::vector<size_t> order;
    for (auto it = first; it != last; ++it) order.push_back(it->second);
    std::sort(order.begin(), order.end());
    for (size_t j : order) {
      const FlatJoint& joint = joints_[j];
      const FlatLink& child = links_[link_index.at(joint.child)];
      if (joint.joint == nullptr) {
        JointSpec weld;
        weld.id = joint.name;
        weld.type = JointType::kFixed;
        weld.parent_body = joint.parent;
        weld.child_body = child.name;
        weld.origin = placed.at(joint.parent).Inverse() * child.pose;
        d.links.push_back(ConvertLink(child));
        d.joints.push_back(weld);
      } else {
        EmitJoint(joint, placed.at(joint.parent), child);
      }
      placed[child.name] = child.pose;
      ++reached;
    }
    for (auto it = order.rbegin(); it != order.rend(); ++it) pending.push_back(joints_[*it].child);
  }
  if (reached < links_.size()) {
    std::string names;
    for (const FlatLink& link : links_) {
      if (placed.count(link.name) == 0) names += (names.empty() ? "" : ", ") + Quoted(link.sdf_name);
    }
    ThrowInvalidArgument(model_field_ + " links " + names + " are joined in a cycle; a robot must be a tree");
  }
  meshes_.ThrowIfMissing("sdf");
  for (const FlatLink& link : links_) {
    ReadSdfInertial(*link.link, link.name, model_field_ + " link " + Quoted(link.sdf_name), &inertials_);
  }
  ResolveInertials("sdf", inertials_, options_, &d, &result_.warnings);
  if (renamed) Warn(model_field_ + " name", Quoted(model.Name()), "robot named " + Quoted(d.name));
  return std::move(result_);
}

}  // namespace

ImportedRobot ConvertSdfModel(const sdf::Model& model, const Pose& model_in_world, const FileLookup& files,
                              const ImportOptions& options, const Limits& limits) {
  SdfConverter converter(files, options, limits);
  return converter.Convert(model, model_in_world);
}

}  // namespace graspsim::import
