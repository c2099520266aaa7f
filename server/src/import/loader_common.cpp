#include "import/loader_common.h"

#include <atomic>
#include <cmath>
#include <filesystem>
#include <optional>

#include <Eigen/Eigenvalues>

#include "core/compute_pool.h"
#include "core/error.h"
#include "core/format.h"
#include "core/validate.h"
#include "import/mass_properties.h"

namespace graspsim::import {
namespace {

// A link that has neither inertial nor geometry is a frame (a tool point, a flange): 1 g and the inertia of a 1 g
// solid sphere of 1 cm radius, 2/5 m r², so a frame behind a moving joint stays integrable.
constexpr double kFrameLinkMass = 1e-3;                            // kg
constexpr double kFrameLinkInertia = 0.4 * kFrameLinkMass * 1e-4;  // kg m^2

Inertial FrameLink() {
  Inertial inertial;
  inertial.mass = kFrameLinkMass;
  inertial.inertia = Mat3::Identity() * kFrameLinkInertia;
  return inertial;
}

std::string Moments(const Mat3& inertia) {
  const Vec3 principal = Eigen::SelfAdjointEigenSolver<Mat3>(inertia).eigenvalues();
  return FormatNumber(principal.x()) + " " + FormatNumber(principal.y()) + " " + FormatNumber(principal.z());
}

bool IsPhysical(const std::string& field, const Mat3& inertia) {
  try {
    CheckInertia(field, inertia);
    return true;
  } catch (const Error&) {
    return false;
  }
}

// The file's inertial in the link frame: the tensor rotated out of the inertial frame, exactly symmetric.
Inertial InLinkFrame(const FileInertial& in) {
  Inertial inertial;
  inertial.mass = in.mass;
  inertial.center_of_mass = in.origin.position;
  const Mat3 R = in.origin.orientation.toRotationMatrix();
  const Mat3 rotated = R * in.inertia * R.transpose();
  inertial.inertia = 0.5 * (rotated + rotated.transpose());
  return inertial;
}

}  // namespace

std::string Quoted(const std::string& name) { return "'" + name + "'"; }

std::string SanitiseName(const std::string& name, bool* changed) {
  std::string result;
  bool other = false;
  for (size_t i = 0; i < name.size(); ++i) {
    const char c = name[i];
    if (c == ':' && i + 1 < name.size() && name[i + 1] == ':') {
      result += '.';
      ++i;
      continue;
    }
    const bool ok = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_' ||
                    c == '-' || c == '.';
    result += ok ? c : '_';
    other = other || !ok;
  }
  if (result.size() > 64) {
    result.resize(64);
    other = true;
  }
  if (result.empty()) {
    result = "unnamed";
    other = true;
  }
  if (changed != nullptr) *changed = other;
  return result;
}

void CheckXmlText(const std::string& format, const std::string& text) {
  const auto* bytes = reinterpret_cast<const unsigned char*>(text.data());
  for (size_t i = 0; i < text.size();) {
    const unsigned char lead = bytes[i];
    const size_t length = lead < 0x80 ? 1 : (lead >> 5) == 0x6 ? 2 : (lead >> 4) == 0xe ? 3 : (lead >> 3) == 0x1e ? 4 : 0;
    bool valid = length > 0 && lead != 0 && i + length <= text.size();
    for (size_t k = 1; valid && k < length; ++k) valid = (bytes[i + k] & 0xc0) == 0x80;
    if (!valid) {
      ThrowInvalidArgument(format + ": " + std::string(lead == 0 ? "a NUL byte" : "text that is not UTF-8") +
                           " at byte " + std::to_string(i));
    }
    i += length;
  }
}

std::string StripMeshUri(const std::string& filename) {
  constexpr std::string_view kPackage = "package://", kModel = "model://", kFile = "file://";
  std::string path = filename;
  if (filename.starts_with(kPackage)) {
    const size_t slash = filename.find('/', kPackage.size());
    path = slash == std::string::npos ? "" : filename.substr(slash + 1);
  } else if (filename.starts_with(kModel)) {
    path = filename.substr(kModel.size());
  } else if (filename.starts_with(kFile)) {
    path = filename.substr(kFile.size());
  }
  while (path.starts_with("/")) path = path.substr(1);  // upload paths are relative: "/meshes/a.stl" as PyBullet
  // Lexically normal, with the leading "./" and "../" a file's own directory layout adds dropped: the client
  // uploads what the model needs under these relative paths (clients/python graspsim/_robot_files.py).
  std::string normal = std::filesystem::path(path).lexically_normal().generic_string();
  while (normal.starts_with("../")) normal = normal.substr(3);
  if (normal.starts_with("./")) normal = normal.substr(2);
  return normal == "." || normal == ".." ? "" : normal;
}

std::vector<std::string> MeshPathCandidates(const std::string& filename) {
  std::vector<std::string> candidates = {StripMeshUri(filename)};
  constexpr std::string_view kPackage = "package://";
  if (filename.starts_with(kPackage)) candidates.push_back(StripMeshUri(filename.substr(kPackage.size())));
  const std::string& path = candidates.front();
  candidates.push_back(path.substr(path.find_last_of('/') + 1));
  return candidates;
}

bool MeshFiles::Load(const std::string& field, const std::string& as_written,
                     const std::vector<std::string>& candidates, const Vec3& scale, Geometry* geometry) {
  const std::string* bytes = nullptr;
  for (const std::string& candidate : candidates) {
    bytes = (files_ && !candidate.empty()) ? files_(candidate) : nullptr;
    if (bytes != nullptr) {
      geometry->mesh_file = candidate;
      break;
    }
  }
  if (bytes == nullptr) {
    if (missing_set_.insert(as_written).second) missing_.push_back(as_written);
    return false;
  }
  CheckFinite(field + " scale", scale);
  const auto key = std::make_tuple(geometry->mesh_file, scale.x(), scale.y(), scale.z());
  auto& cached = cache_[key];
  if (cached == nullptr) {
    cached = LoadSharedMeshFile(field, geometry->mesh_file, *bytes, scale, limits_);
  }
  geometry->mesh = cached;
  return true;
}

void MeshFiles::Prefetch(const std::vector<Request>& requests) {
  struct Job {
    std::tuple<std::string, double, double, double> key;
    std::string field, path;
    const std::string* bytes;
    Vec3 scale;
  };
  std::vector<Job> jobs;
  std::set<std::tuple<std::string, double, double, double>> queued;
  for (const Request& request : requests) {
    for (const std::string& candidate : request.candidates) {
      const std::string* bytes = (files_ && !candidate.empty()) ? files_(candidate) : nullptr;
      if (bytes == nullptr) continue;
      auto key = std::make_tuple(candidate, request.scale.x(), request.scale.y(), request.scale.z());
      if (!cache_.count(key) && request.scale.allFinite() && queued.insert(key).second) {
        jobs.push_back({key, request.field, candidate, bytes, request.scale});
      }
      break;
    }
  }
  if (jobs.size() < 2) return;  // nothing to overlap: Load parses it
  std::vector<std::shared_ptr<const TriangleMesh>> parsed(jobs.size());
  std::atomic<size_t> next{0};
  ComputePool::Shared().Run(jobs.size(), [&](size_t) {
    for (size_t i = next.fetch_add(1); i < jobs.size(); i = next.fetch_add(1)) {
      try {
        parsed[i] = LoadSharedMeshFile(jobs[i].field, jobs[i].path, *jobs[i].bytes, jobs[i].scale, limits_);
      } catch (const Error&) {
        // Load parses it again and reports it with its field
      }
    }
  });
  for (size_t i = 0; i < jobs.size(); ++i) {
    if (parsed[i]) cache_[jobs[i].key] = std::move(parsed[i]);
  }
}

void MeshFiles::ThrowIfMissing(const std::string& format) const {
  if (missing_.empty()) return;
  std::string list;
  for (const std::string& name : missing_) list += (list.empty() ? "" : ", ") + Quoted(name);
  ThrowInvalidArgument(format + ": " + std::to_string(missing_.size()) + " mesh file" +
                       (missing_.size() == 1 ? " the model names was" : "s the model names were") +
                       " not uploaded: " + list);
}

void ResolveInertials(const std::string& format, const FileInertials& file, const ImportOptions& options,
                      RobotDescription* description, std::vector<ImportWarning>* warnings) {
  std::map<std::string, const JointSpec*> parent_joint;
  for (const JointSpec& joint : description->joints) parent_joint[joint.child_body] = &joint;
  const bool from_file_only = options.strict || options.inertia == InertiaSource::kFromFile;
  const double density = options.density > 0 ? options.density : 1000.0;
  const std::string at_density = "at " + FormatNumber(density) + " kg/m^3";

  for (BodySpec& link : description->links) {
    const auto found = file.find(link.id);
    const FileInertial* in = found == file.end() ? nullptr : &found->second;
    if (in != nullptr && in->massless) {
      link.inertial = Inertial{};  // massless by design: the chain's last link carries the mass
      continue;
    }
    const auto joint_it = parent_joint.find(link.id);
    const JointSpec* joint = joint_it == parent_joint.end() ? nullptr : joint_it->second;
    const bool fixed_to_parent = joint == nullptr || joint->type == JointType::kFixed;
    const std::string field = in != nullptr ? in->field : format + ": link " + Quoted(link.id) + " inertial";
    const bool has_geometry = !link.collision.empty();
    const auto warn = [&](const std::string& element, const std::string& value, const std::string& action) {
      warnings->push_back({element, value, action});
    };
    // The solid collision geometry's mass properties, computed only where a rule below needs them (a mesh's
    // volume integral is not free, and most links' inertials are kept as the file gives them).
    std::optional<Inertial> solid;
    const auto geometric = [&]() -> const Inertial& {
      if (!solid) solid = has_geometry ? SolidMassProperties(link.collision, density) : Inertial{};
      return *solid;
    };

    if (in == nullptr) {
      if (!has_geometry) {
        // URDF's meaning of a link with no inertial: massless. Fixed to its parent (a tool point, a flange) it is
        // a frame of the parent; behind a moving joint it needs some inertia to be integrable.
        link.inertial = fixed_to_parent ? Inertial{} : FrameLink();
        continue;
      }
      if (from_file_only) {
        ThrowInvalidArgument(format + ": link " + Quoted(link.id) +
                             " has collision geometry but no <inertial>; give it a mass and an inertia");
      }
      if (geometric().mass > 0) {
        link.inertial = geometric();
        warn(field, "absent", "from the collision geometry " + at_density + ": " + FormatNumber(geometric().mass) + " kg");
      } else {
        link.inertial = FrameLink();
        warn(field, "absent", "the collision geometry encloses no volume: a 1 g frame");
      }
      continue;
    }

    const std::string mass_field = field + " mass (kg)";
    if (!std::isfinite(in->mass) || in->mass < 0 || (options.strict && in->mass == 0)) {
      CheckPositive(mass_field, in->mass);  // throws, naming the value
    }
    if (options.inertia == InertiaSource::kFromGeometry && geometric().mass > 0 && !(in->mass == 0 && fixed_to_parent)) {
      link.inertial = geometric();  // asked for: not a repair
      continue;
    }
    if (in->mass == 0) {
      if (fixed_to_parent) {
        link.inertial = Inertial{};
        warn(mass_field, "0",
             joint != nullptr ? "massless frame, merged into its parent link " + Quoted(joint->parent_body) +
                                    " (it adds no mass and keeps its frame)"
                              : "massless root link: the robot's fixed base");
        continue;
      }
      if (from_file_only) {
        ThrowInvalidArgument(mass_field + ": 0 must be > 0 for a link behind the moving joint " + Quoted(joint->id));
      }
      link.inertial = geometric().mass > 0 ? geometric() : FrameLink();
      warn(mass_field, "0",
           geometric().mass > 0 ? "behind the moving joint " + Quoted(joint->id) + ": from the collision geometry " +
                                    at_density + ", " + FormatNumber(geometric().mass) + " kg"
                              : "behind the moving joint " + Quoted(joint->id) + " with no collision volume: a 1 g frame");
      continue;
    }

    link.inertial = InLinkFrame(*in);
    if (IsPhysical(field, link.inertial.inertia)) continue;
    if (from_file_only) CheckInertia(field, link.inertial.inertia);  // throws with today's message
    const std::string found_moments = Moments(link.inertial.inertia);
    if (geometric().mass > 0) {
      // PyBullet's default: the file's mass, the inertia of the collision shape.
      link.inertial.inertia = geometric().inertia * (in->mass / geometric().mass);
      warn(field + " principal moments (kg m^2)", found_moments,
           "not a physical inertia: the collision geometry's, scaled to the file's mass " + FormatNumber(in->mass) + " kg");
    } else {
      // MuJoCo's balanceinertia, made positive: the mean moment on every axis.
      const double mean = std::max(link.inertial.inertia.trace() / 3.0, 0.4 * in->mass * 1e-4);
      link.inertial.inertia = Mat3::Identity() * mean;
      warn(field + " principal moments (kg m^2)", found_moments,
           "not a physical inertia and no collision volume: " + FormatNumber(mean) + " on every axis");
    }
  }
}

namespace {

void AppendChainJoint(const std::string& id, JointType type, const Vec3& axis, double limit, const Pose& origin,
                      const std::string& parent, const std::string& child, RobotDescription* description) {
  JointSpec spec;
  spec.id = id;
  spec.type = type;
  spec.parent_body = parent;
  spec.child_body = child;
  spec.origin = origin;
  spec.axis = axis;
  if (type != JointType::kContinuous) {
    spec.lower = -limit;
    spec.upper = limit;
  }
  description->joints.push_back(std::move(spec));
}

// `name` + `suffix` within graspsim's 64 characters (core/validate.h CheckName): the name is shortened, not the suffix.
std::string WithSuffix(const std::string& name, const std::string& suffix) {
  constexpr size_t kMaxName = 64;
  return name.substr(0, kMaxName - std::min(kMaxName, suffix.size())) + suffix;
}

// Appends joints `axes` (type per entry) from joint.parent_body to joint.child_body through new massless links.
void AppendChain(const JointSpec& joint, const std::vector<std::tuple<std::string, JointType, Vec3, double>>& axes,
                 RobotDescription* description, FileInertials* file) {
  auto child_at = std::find_if(description->links.begin(), description->links.end(),
                               [&](const BodySpec& b) { return b.id == joint.child_body; });
  if (child_at == description->links.end()) {
    throw Error(ErrorCode::kInternal, "import: chain joint " + Quoted(joint.id) + " has no child link");
  }
  std::vector<BodySpec> chain_links;
  std::string parent = joint.parent_body;
  for (size_t i = 0; i < axes.size(); ++i) {
    const auto& [suffix, type, axis, limit] = axes[i];
    const bool last = i + 1 == axes.size();
    const std::string child = last ? joint.child_body : WithSuffix(joint.child_body, "__" + suffix);
    AppendChainJoint(WithSuffix(joint.id, "_" + suffix), type, axis, limit, i == 0 ? joint.origin : Pose{}, parent,
                     child, description);
    if (!last) {
      BodySpec link;
      link.id = child;
      link.motion = BodyMotion::kArticulated;
      chain_links.push_back(link);
      FileInertial massless;
      massless.massless = true;
      (*file)[child] = massless;
    }
    parent = child;
  }
  description->links.insert(child_at, chain_links.begin(), chain_links.end());
}

}  // namespace

void AppendBallJoint(const JointSpec& joint, double limit, RobotDescription* description, FileInertials* file) {
  const JointType type = limit > 0 ? JointType::kRevolute : JointType::kContinuous;
  AppendChain(joint,
              {{"x", type, Vec3::UnitX(), limit}, {"y", type, Vec3::UnitY(), limit}, {"z", type, Vec3::UnitZ(), limit}},
              description, file);
}

void AppendFreeJoint(const JointSpec& joint, double translation_limit, RobotDescription* description,
                     FileInertials* file) {
  const double reach = translation_limit > 0 ? translation_limit : 1e3;  // m: prismatic joints are limited
  AppendChain(joint,
              {{"px", JointType::kPrismatic, Vec3::UnitX(), reach},
               {"py", JointType::kPrismatic, Vec3::UnitY(), reach},
               {"pz", JointType::kPrismatic, Vec3::UnitZ(), reach},
               {"x", JointType::kContinuous, Vec3::UnitX(), 0},
               {"y", JointType::kContinuous, Vec3::UnitY(), 0},
               {"z", JointType::kContinuous, Vec3::UnitZ(), 0}},
              description, file);
}

}  // namespace graspsim::import

namespace graspsim {

Inertial ObjectInertialFromGeometry(const std::string& field, const std::vector<Geometry>& geometry,
                                    const ImportOptions& options, std::vector<ImportWarning>* warnings) {
  if (options.strict || options.inertia == InertiaSource::kFromFile) {
    ThrowInvalidArgument(field + ": required when a moving object is given by geometry (import_options " +
                         (options.strict ? "strict" : "inertia FROM_FILE") + ")");
  }
  const double density = options.density > 0 ? options.density : 1000.0;
  const Inertial inertial = SolidMassProperties(geometry, density);
  if (!(inertial.mass > 0)) {
    ThrowInvalidArgument(field + ": required: the geometry encloses no volume to take a mass from");
  }
  warnings->push_back({field, "absent", "from the geometry at " + FormatNumber(density) + " kg/m^3: " +
                                            FormatNumber(inertial.mass) + " kg"});
  return inertial;
}

}  // namespace graspsim
