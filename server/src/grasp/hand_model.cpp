// Builds a HandModel from a HandSpec: link arrays, surface samples, BVHs, finger motions.
#include "grasp/hand_model.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <numbers>

#include "collision/tessellation.h"
#include "core/error.h"
#include "world/state.h"

namespace graspsim::grasp {
namespace {

// Largest gap between a sample's circular path and the straight chord the simulation casts along, m.
constexpr double kChordSagitta = 1e-4;

int Steps(double length, double spacing) { return std::max(1, static_cast<int>(std::ceil(length / spacing))); }

// Samples of a box surface: a lattice on each face, edges and corners included, each with its face's normal
// (points on an edge appear once per face, so both faces' sweeps see them).
void SampleBox(const Vec3& half, double spacing, std::vector<Vec3>* points, std::vector<Vec3>* normals) {
  for (int axis = 0; axis < 3; ++axis) {
    const int u = (axis + 1) % 3, v = (axis + 2) % 3;
    const int nu = Steps(2 * half[u], spacing), nv = Steps(2 * half[v], spacing);
    for (int side = -1; side <= 1; side += 2) {
      Vec3 n = Vec3::Zero();
      n[axis] = side;
      for (int i = 0; i <= nu; ++i) {
        for (int j = 0; j <= nv; ++j) {
          Vec3 p;
          p[axis] = side * half[axis];
          p[u] = -half[u] + 2 * half[u] * i / nu;
          p[v] = -half[v] + 2 * half[v] * j / nv;
          points->push_back(p);
          normals->push_back(n);
        }
      }
    }
  }
}

void SampleCylinder(double radius, double half_length, double spacing, std::vector<Vec3>* points,
                    std::vector<Vec3>* normals) {
  const int around = std::max(8, Steps(2 * std::numbers::pi * radius, spacing));
  const int along = Steps(2 * half_length, spacing);
  for (int k = 0; k < around; ++k) {
    const double a = 2 * std::numbers::pi * k / around;
    const Vec3 n(std::cos(a), std::sin(a), 0);
    for (int i = 0; i <= along; ++i) {
      points->push_back(Vec3(radius * n.x(), radius * n.y(), -half_length + 2 * half_length * i / along));
      normals->push_back(n);
    }
  }
  const int rings = Steps(radius, spacing);
  for (int side = -1; side <= 1; side += 2) {
    points->push_back(Vec3(0, 0, side * half_length));
    normals->push_back(Vec3(0, 0, side));
    for (int r = 1; r <= rings; ++r) {
      const double rr = radius * r / rings;
      const int count = std::max(6, Steps(2 * std::numbers::pi * rr, spacing));
      for (int k = 0; k < count; ++k) {
        const double a = 2 * std::numbers::pi * k / count;
        points->push_back(Vec3(rr * std::cos(a), rr * std::sin(a), side * half_length));
        normals->push_back(Vec3(0, 0, side));
      }
    }
  }
}

void SampleSphere(double radius, double spacing, std::vector<Vec3>* points, std::vector<Vec3>* normals) {
  const double area = 4 * std::numbers::pi * radius * radius;
  const int count = std::max(32, static_cast<int>(std::ceil(area / (spacing * spacing))));
  const double golden = std::numbers::pi * (3 - std::sqrt(5.0));
  for (int i = 0; i < count; ++i) {
    const double z = 1 - 2 * (i + 0.5) / count, r = std::sqrt(1 - z * z);
    const Vec3 n(r * std::cos(golden * i), r * std::sin(golden * i), z);
    points->push_back(radius * n);
    normals->push_back(n);
  }
}

// A mesh geometry's vertices with area-weighted vertex normals.
void SampleMesh(const TriangleMesh& mesh, std::vector<Vec3>* points, std::vector<Vec3>* normals) {
  std::vector<Vec3> vertex_normals(mesh.vertices.size(), Vec3::Zero());
  for (const auto& t : mesh.triangles) {
    const Vec3 a = mesh.vertices[t[0]].cast<double>();
    const Vec3 n = (mesh.vertices[t[1]].cast<double>() - a).cross(mesh.vertices[t[2]].cast<double>() - a);
    for (uint32_t i : t) vertex_normals[i] += n;
  }
  for (size_t i = 0; i < mesh.vertices.size(); ++i) {
    if (vertex_normals[i].norm() == 0) continue;  // not referenced by a triangle
    points->push_back(mesh.vertices[i].cast<double>());
    normals->push_back(vertex_normals[i].normalized());
  }
}

// Tessellation, samples and box of one collision geometry, placed by its origin into the link frame.
void AddGeometry(const Geometry& g, double spacing, collision::LocalMesh* surface, HandLink* link) {
  collision::LocalMesh local;
  std::vector<Vec3> points, normals;
  LinkBox box;
  switch (g.kind) {
    case Geometry::Kind::kBox:
      local = collision::BoxMesh(0.5 * g.box_size);
      SampleBox(0.5 * g.box_size, spacing, &points, &normals);
      box.half = 0.5 * g.box_size;
      break;
    case Geometry::Kind::kSphere:
      local = collision::SphereMesh(g.radius);
      SampleSphere(g.radius, spacing, &points, &normals);
      box.half = Vec3::Constant(g.radius);
      break;
    case Geometry::Kind::kCylinder:
      local = collision::CylinderMesh(g.radius, 0.5 * g.length);
      SampleCylinder(g.radius, 0.5 * g.length, spacing, &points, &normals);
      box.half = Vec3(g.radius, g.radius, 0.5 * g.length);
      break;
    case Geometry::Kind::kMesh: {
      for (const auto& v : g.mesh->vertices) local.vertices.push_back(v.cast<double>());
      local.triangles = g.mesh->triangles;
      SampleMesh(*g.mesh, &points, &normals);
      Vec3 lo = Vec3::Constant(std::numeric_limits<double>::infinity()), hi = -lo;
      for (const Vec3& v : local.vertices) lo = lo.cwiseMin(v), hi = hi.cwiseMax(v);
      box.centre = 0.5 * (lo + hi);
      box.half = 0.5 * (hi - lo);
      break;
    }
  }
  const Mat3 rotation = g.origin.orientation.toRotationMatrix();
  const uint32_t base = static_cast<uint32_t>(surface->vertices.size());
  for (const Vec3& v : local.vertices) surface->vertices.push_back(g.origin * v);
  for (const auto& t : local.triangles) surface->triangles.push_back({t[0] + base, t[1] + base, t[2] + base});
  for (size_t i = 0; i < points.size(); ++i) {
    link->samples.push_back(g.origin * points[i]);
    link->normals.push_back(rotation * normals[i]);
    link->reach = std::max(link->reach, link->samples.back().norm());
  }
  box.centre = g.origin * box.centre;
  box.axes = rotation;
  link->boxes.push_back(box);
}

}  // namespace

HandModel::HandModel(const HandSpec& spec, double sample_spacing)
    : name_(spec.name), roll_period_(spec.roll_period) {
  const RobotDescription& robot = spec.robot;
  std::map<std::string, int> link_index, joint_index;
  for (const BodySpec& body : robot.links) {
    link_index[body.id] = static_cast<int>(links_.size());
    HandLink& link = links_.emplace_back();
    link.name = body.id;
    collision::LocalMesh surface;
    for (const Geometry& g : body.collision) AddGeometry(g, sample_spacing, &surface, &link);
    for (uint32_t i = 0; i < link.samples.size(); ++i) {
      if (link.runs.empty() || link.normals[i] != link.runs.back().normal) link.runs.push_back({i, i, link.normals[i]});
      link.runs.back().end = i + 1;
    }
    for (SampleRun& run : link.runs) {
      Vec3 lo = link.samples[run.begin], hi = lo;
      for (uint32_t i = run.begin; i < run.end; ++i) lo = lo.cwiseMin(link.samples[i]), hi = hi.cwiseMax(link.samples[i]);
      run.centre = 0.5 * (lo + hi);
      run.radius = 0.5 * (hi - lo).norm();
    }
    if (surface.triangles.empty()) continue;
    TriangleMesh mesh;  // in float, as Embree casts
    for (const Vec3& v : surface.vertices) mesh.vertices.push_back(v.cast<float>());
    mesh.triangles = surface.triangles;
    link.bvh = std::make_unique<collision::EmbreeScene>(mesh, RTC_BUILD_QUALITY_HIGH);  // built once per planner
    for (const auto& t : surface.triangles) {
      const Vec3 n = (surface.vertices[t[1]] - surface.vertices[t[0]]).cross(surface.vertices[t[2]] - surface.vertices[t[0]]);
      link.face_normals.push_back(n.norm() > 0 ? Vec3(n.normalized()) : Vec3::Zero());
    }
  }
  for (const JointSpec& spec_joint : robot.joints) {
    joint_index[spec_joint.id] = static_cast<int>(joints_.size());
    HandJoint& joint = joints_.emplace_back();
    joint.name = spec_joint.id;
    joint.type = spec_joint.type;
    joint.parent_link = link_index.at(spec_joint.parent_body);
    joint.child_link = link_index.at(spec_joint.child_body);
    joint.origin = spec_joint.origin;
    joint.axis = spec_joint.axis;
    joint.lower = spec_joint.lower;
    joint.upper = spec_joint.upper;
    links_[joint.child_link].parent_joint = static_cast<int>(joints_.size()) - 1;
  }
  for (size_t j = 0; j < robot.joints.size(); ++j) {
    if (!robot.joints[j].mimic) continue;
    joints_[j].leader = joint_index.at(robot.joints[j].mimic->joint_id);
    joints_[j].multiplier = robot.joints[j].mimic->multiplier;
    joints_[j].offset = robot.joints[j].mimic->offset;
  }
  auto find_joint = [&](const std::string& name) {
    const auto it = joint_index.find(name);
    if (it == joint_index.end()) throw Error(ErrorCode::kInternal, "hand " + name_ + ": no joint " + name);
    return it->second;
  };

  for (const Preshape& preshape : spec.preshapes) {
    std::vector<double> q(joints_.size(), 0.0);
    for (const auto& [name, value] : preshape.joint_positions) q[find_joint(name)] = value;
    for (size_t j = 0; j < joints_.size(); ++j) {
      if (joints_[j].leader >= 0) q[j] = joints_[j].multiplier * q[joints_[j].leader] + joints_[j].offset;
    }
    preshapes_.push_back(std::move(q));
    preshape_names_.push_back(preshape.name);
  }

  for (const FingerSpec& finger_spec : spec.fingers) {
    HandFinger& finger = fingers_.emplace_back();
    finger.name = finger_spec.name;
    std::vector<bool> driven(joints_.size(), false);
    for (const auto& [name, rate] : finger_spec.joint_rates) driven[find_joint(name)] = true;
    for (const FingerSpec& other : spec.fingers) {  // a joint driven by any finger moves only with it
      for (const auto& [name, rate] : other.joint_rates) driven[find_joint(name)] = true;
    }
    for (const auto& [name, rate] : finger_spec.joint_rates) finger.joint_rates.push_back({find_joint(name), rate});
    for (size_t j = 0; j < joints_.size(); ++j) {
      if (driven[j] || joints_[j].leader < 0) continue;
      for (const auto& [leader, rate] : std::vector(finger.joint_rates)) {
        if (leader == joints_[j].leader) finger.joint_rates.push_back({static_cast<int>(j), joints_[j].multiplier * rate});
      }
    }
    // Moving links: the children of moved joints and everything below them (joints are in topological order).
    std::vector<bool> moves(links_.size(), false);
    for (const auto& [j, rate] : finger.joint_rates) moves[joints_[j].child_link] = true;
    for (const HandJoint& joint : joints_) {
      if (moves[joint.parent_link]) moves[joint.child_link] = true;
    }
    double reach = 0;
    for (size_t l = 0; l < links_.size(); ++l) {
      if (!moves[l]) continue;
      finger.links.push_back(static_cast<int>(l));
    }
    double turn_rate = 0;  // rad per unit s, summed over the chain: bounds every link's rotation per step
    for (const auto& [j, rate] : finger.joint_rates) {
      if (joints_[j].type == JointType::kRevolute || joints_[j].type == JointType::kContinuous) turn_rate += std::abs(rate);
    }
    // The sagitta bound needs each moving sample's distance from the axes it turns about: at most its distance
    // from the finger's first joint, over the pre-shapes (the finger's links keep their shape otherwise).
    std::vector<Pose> poses(links_.size());
    const HandJoint& first = joints_[finger.joint_rates.front().first];
    for (const std::vector<double>& q : preshapes_) {
      LinkPoses(Pose(), q, &poses);
      const Vec3 pivot = poses[first.parent_link] * first.origin.position;
      for (int l : finger.links) {
        for (const Vec3& sample : links_[l].samples) reach = std::max(reach, (poses[l] * sample - pivot).norm());
      }
    }
    finger.straight = turn_rate == 0;
    finger.max_step = finger.straight ? std::numeric_limits<double>::infinity()
                                      : std::sqrt(8 * kChordSagitta / std::max(reach, 1e-3)) / turn_rate;
  }
}

double HandModel::ClosingRange(size_t f, const std::vector<double>& q) const {
  double range = std::numeric_limits<double>::infinity();
  for (const auto& [j, rate] : fingers_[f].joint_rates) {
    const HandJoint& joint = joints_[j];
    if (joint.type == JointType::kContinuous || rate == 0) continue;
    const double room = rate > 0 ? joint.upper - q[j] : q[j] - joint.lower;
    range = std::min(range, std::max(0.0, room) / std::abs(rate));
  }
  return std::isfinite(range) ? range : 0.0;
}

void HandModel::LinkPoses(const Pose& base, const std::vector<double>& q, std::vector<Pose>* poses) const {
  (*poses)[0] = base;
  for (size_t j = 0; j < joints_.size(); ++j) {
    const HandJoint& joint = joints_[j];
    (*poses)[joint.child_link] = (*poses)[joint.parent_link] * joint.origin * JointMotion(joint.type, joint.axis, q[j]);
  }
}

}  // namespace graspsim::grasp
