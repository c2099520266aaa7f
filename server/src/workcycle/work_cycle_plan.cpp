// The work cycle's request checks and its geometry: grasp height from the coverage, finger opening from the
// object's width. Everything is measured by forward kinematics of the scene's own model, so any robot with the
// required joints and pads works, not only the built-in one.
#include <algorithm>
#include <cmath>

#include "core/error.h"
#include "core/format.h"
#include "physics/builtin_drives.h"
#include "tactile/pad_elements.h"
#include "workcycle/work_cycle.h"

namespace graspsim {
namespace {

constexpr double kFingertipClearance = 0.002;  // m the fingertips stay above the object's support
constexpr double kOpeningClearance = 0.005;    // m between each open pad and the object
constexpr double kMaxLift = 1.0;               // m
constexpr double kMaxHoldTime = 600;           // s

std::string Num(double value) { return FormatNumber(value); }
std::string Mm(double metres) { return FormatNumber(std::round(metres * 1e4) / 10) + " mm"; }
std::string M(double metres) { return FormatNumber(std::round(metres * 1e5) / 1e5) + " m"; }

struct Bounds {
  Vec3 min = Vec3::Constant(INFINITY), max = Vec3::Constant(-INFINITY);
  bool Empty() const { return !(min.x() <= max.x()); }
  void Add(const Vec3& p) {
    min = min.cwiseMin(p);
    max = max.cwiseMax(p);
  }
};

// World bounds of a body's collision geometry at `pose` (boxes and cylinders by their corners, meshes by their
// vertices, spheres exactly).
Bounds BodyBounds(const BodySpec& body, const Pose& pose) {
  Bounds bounds;
  for (const Geometry& g : body.collision) {
    const Pose frame = pose * g.origin;
    Vec3 half = Vec3::Zero();
    switch (g.kind) {
      case Geometry::Kind::kSphere:
        bounds.Add(frame.position - Vec3::Constant(g.radius));
        bounds.Add(frame.position + Vec3::Constant(g.radius));
        continue;
      case Geometry::Kind::kMesh:
        for (const Eigen::Vector3f& v : g.mesh->vertices) bounds.Add(frame * v.cast<double>());
        continue;
      case Geometry::Kind::kBox:
        half = g.box_size / 2;
        break;
      case Geometry::Kind::kCylinder:
        half = Vec3(g.radius, g.radius, g.length / 2);
        break;
    }
    for (int corner = 0; corner < 8; ++corner) {
      bounds.Add(frame * Vec3(corner & 1 ? half.x() : -half.x(), corner & 2 ? half.y() : -half.y(),
                              corner & 4 ? half.z() : -half.z()));
    }
  }
  return bounds;
}

void CheckRange(const std::string& field, double value, double low, double high, const std::string& unit,
                bool low_open) {
  const bool ok = std::isfinite(value) && (low_open ? value > low : value >= low) && value <= high;
  if (!ok) {
    ThrowInvalidArgument(field + ": " + Num(value) + unit + " is out of range; give a value in " +
                         (low_open ? "(" : "[") + Num(low) + ", " + Num(high) + "]" + unit);
  }
}

}  // namespace

WorkCycle::WorkCycle(std::shared_ptr<const SceneModel> model, const SceneState& state,
                     const WorkCycleRequest& request)
    : model_(std::move(model)), request_(request) {
  const SceneModel& m = *model_;
  dt_ = m.simulation.time_step;
  control_steps_ = std::max<uint64_t>(1, std::llround(0.01 / dt_));
  CheckRange("coverage", request.coverage, 0, 1, "", true);
  CheckRange("lift_height", request.lift_height, 0, kMaxLift, " m", true);
  CheckRange("hold_time", request.hold_time, 0, kMaxHoldTime, " s", false);
  // One frame per step at most (1 / time_step, rounded for the message; the check allows its rounding error).
  if (request.frame_rate_hz > 1 / dt_ && request.frame_rate_hz <= 1 / dt_ * (1 + 1e-9)) {
    request_.frame_rate_hz = 1 / dt_;
  }
  CheckRange("frame_rate_hz", request_.frame_rate_hz, 0, 1 / dt_, " Hz", true);
  if (!std::isfinite(request.tactile_setpoint) || request.tactile_setpoint <= 0) {
    ThrowInvalidArgument("tactile_setpoint: " + Num(request.tactile_setpoint) + " is not an intensity sum > 0");
  }

  const std::string& id = request.gripper_id;
  if (id.empty()) ThrowInvalidArgument("gripper_id: empty; name the robot that carries the gripper");
  const auto robot = m.robot_index.find(id);
  if (robot == m.robot_index.end()) ThrowNotFound("gripper_id: no robot '" + id + "' in the scene");
  robot_ = robot->second;
  const RobotSpec& spec = m.robots[robot_];
  auto joint = [&](const std::string& name, const char* role) {
    const auto found = m.joint_index.find(id + "/" + name);
    if (found == m.joint_index.end() || m.joints[found->second].type != JointType::kPrismatic ||
        m.joints[found->second].mimic) {
      ThrowInvalidArgument("gripper_id: robot '" + id + "' has no independent prismatic joint '" + id + "/" + name +
                           "' (" + role + "); the work cycle runs a gripper on a z axis, e.g. the built-in "
                           "schunk_pg70_on_z_axis");
    }
    return found->second;
  };
  axis_ = joint("z_axis", "the vertical axis");
  finger_ = joint("finger_left_joint", "the fingers");
  if (spec.tactile_array_ids.size() != 2) {
    ThrowInvalidArgument("gripper_id: robot '" + id + "' has " + std::to_string(spec.tactile_array_ids.size()) +
                         " tactile arrays; the work cycle needs two, one per finger");
  }
  for (size_t i = 0; i < 2; ++i) {
    pad_ids_[i] = spec.tactile_array_ids[i];
    pads_[i] = m.tactile_index.at(pad_ids_[i]);
  }

  const std::string& object = request.object_id;
  if (object.empty()) ThrowInvalidArgument("object_id: empty; name the object to pick");
  const auto body = m.body_index.find(object);
  if (body == m.body_index.end()) ThrowNotFound("object_id: no body '" + object + "' in the scene");
  object_ = body->second;
  if (m.bodies[object_].motion != BodyMotion::kFree) {
    ThrowInvalidArgument("object_id: '" + object + "' is " +
                         (m.bodies[object_].motion == BodyMotion::kStatic ? "static" : "a robot's link") +
                         "; the work cycle picks a free body");
  }
  if (m.bodies[object_].collision.empty()) {
    ThrowInvalidArgument("object_id: '" + object + "' has no collision geometry; the pads cannot touch it");
  }

  // The installed motors if any (SetActuators with a motor), else the built-in drives.
  auto drive = [&](size_t j) {
    const auto installed = state.actuators.find(j);
    return installed != state.actuators.end() ? installed->second.motor : BuiltinDrive(spec, m.joints[j]);
  };
  axis_drive_ = drive(axis_);
  finger_drive_ = drive(finger_);
  const TactileArraySpec& pad = m.tactile_arrays[pads_[0]];
  // The drive's joint force is shared by the driven finger and its mimics (virtual work: F δq = Σ F_i m_i δq):
  // the PG70's 200 N at 3.5 A is the datasheet's sum over both jaws, 100 N on each pad.
  double share = 1;
  for (const JointSpec& other : m.joints) {
    if (other.mimic && other.mimic->joint_id == m.joints[finger_].id) share += std::abs(other.mimic->multiplier);
  }
  const double newtons_per_amp = finger_drive_.ratio * finger_drive_.efficiency * finger_drive_.torque_constant / share;
  amps_per_count_ = 1 / (pad.intensity_per_newton * newtons_per_amp);
  // Twice the current the set-point needs: room to correct, but a set-point the pads cannot reach (saturated
  // texels) does not wind the grip up to the drive's full force.
  current_cap_ = std::min(finger_drive_.current_limit, 2 * request.tactile_setpoint * amps_per_count_);
  Plan(state);
}

void WorkCycle::Plan(const SceneState& state) {
  const SceneModel& m = *model_;
  const std::string& id = request_.gripper_id;
  const JointSpec& axis = m.joints[axis_];
  const JointSpec& finger = m.joints[finger_];
  const TactileArraySpec& pad0 = m.tactile_arrays[pads_[0]];
  const double length = pad0.rows * pad0.pitch;  // m along the finger

  // The gripper's geometry with the axis at qa and the fingers at qf (mimic fingers follow).
  struct Placement {
    double tip = INFINITY, fingertip = INFINITY, gap = 0;
    Vec3 centre = Vec3::Zero(), normal = Vec3::Zero();
    std::array<Vec3, 2> along{};  // the pads' row direction (toward the tip), world
  };
  auto measure = [&](double qa, double qf) {
    SceneState s = state;
    s.joint_positions[axis_] = qa;
    s.joint_positions[finger_] = qf;
    for (size_t j = 0; j < m.joints.size(); ++j) {
      const JointSpec& follower = m.joints[j];
      if (follower.mimic && follower.mimic->joint_id == finger.id) {
        s.joint_positions[j] = follower.mimic->multiplier * qf + follower.mimic->offset;
      }
    }
    UpdateRobotLinkPoses(m, robot_, &s);
    Placement g;
    std::array<Vec3, 2> surface;
    for (size_t i = 0; i < 2; ++i) {
      const TactileArraySpec& pad = m.tactile_arrays[pads_[i]];
      const size_t link = m.body_index.at(pad.body_id);
      const Pose frame = s.body_poses[link] * pad.origin;
      g.along[i] = frame.orientation * Vec3::UnitY();
      g.tip = std::min(g.tip, (frame.position + pad.rows * pad.pitch / 2 * g.along[i]).z());
      surface[i] = frame * Vec3(0, 0, pad.thickness);
      if (i == 0) g.normal = frame.orientation * Vec3::UnitZ();
      const Bounds link_bounds = BodyBounds(m.bodies[link], s.body_poses[link]);
      if (!link_bounds.Empty()) g.fingertip = std::min(g.fingertip, link_bounds.min.z());
    }
    g.fingertip = std::min(g.fingertip, g.tip);
    g.centre = (surface[0] + surface[1]) / 2;
    g.gap = (surface[1] - surface[0]).dot(g.normal);
    return g;
  };

  const double qa0 = state.joint_positions[axis_], qf0 = state.joint_positions[finger_];
  const Placement now = measure(qa0, qf0);
  for (const Vec3& along : now.along) {
    if (along.z() > -0.99) {
      ThrowInvalidArgument("gripper_id: the pads of '" + id + "' run along (" + Num(along.x()) + ", " +
                           Num(along.y()) + ", " + Num(along.z()) + ") toward their tips, not down; the work cycle "
                           "grasps from above: place the robot so that its fingers point along -z");
    }
  }
  // Prismatic joints move the gripper rigidly: the tip height is linear in the axis position.
  const double dtip_dq = measure(qa0 + 0.01, qf0).tip - now.tip;
  if (std::abs(dtip_dq / 0.01) < 0.999) {
    ThrowInvalidArgument("gripper_id: joint '" + axis.id + "' does not move the gripper vertically (" +
                         Num(dtip_dq / 0.01) + " m of height per m); place the robot with its axis along z");
  }
  const double height_per_q = dtip_dq / 0.01;

  const Bounds object = BodyBounds(m.bodies[object_], state.body_poses[object_]);
  const std::string& name = request_.object_id;
  if (now.centre.x() < object.min.x() || now.centre.x() > object.max.x() || now.centre.y() < object.min.y() ||
      now.centre.y() > object.max.y()) {
    ThrowInvalidArgument("object_id: '" + name + "' (x " + M(object.min.x()) + " .. " + M(object.max.x()) + ", y " +
                         M(object.min.y()) + " .. " + M(object.max.y()) + ") is not below the pads of '" + id +
                         "' (centred at x " + M(now.centre.x()) + ", y " + M(now.centre.y()) +
                         "); place it under the fingers");
  }
  if (object.max.z() >= now.fingertip) {
    ThrowInvalidArgument("object_id: the top of '" + name + "' (z " + M(object.max.z()) +
                         ") is not below the fingertips of '" + id + "' (z " + M(now.fingertip) +
                         "); the gripper must start above the object");
  }

  // Grasp height: the pads' tips `coverage` of their length below the object's top, but the fingertips at least
  // kFingertipClearance above the object's bottom (its support).
  const double overhang = now.tip - now.fingertip;  // fingertips below the pads' tips
  const double wanted_tip = object.max.z() - request_.coverage * length;
  const double lowest_tip = object.min.z() + kFingertipClearance + overhang;
  const double tip = std::max(wanted_tip, lowest_tip);
  summary_.coverage = (object.max.z() - tip) / length;
  if (summary_.coverage <= 0) {
    ThrowInvalidArgument("object_id: '" + name + "' is " + Mm(object.max.z() - object.min.z()) +
                         " tall; the pads cannot reach it with the fingertips " + Mm(kFingertipClearance) +
                         " above its support");
  }
  summary_.grasp_position = qa0 + (tip - now.tip) / height_per_q;
  lift_position_ = request_.lift_height / height_per_q;
  const double top = summary_.grasp_position + lift_position_;
  auto within = [&](double q) { return q >= axis.lower - 1e-12 && q <= axis.upper + 1e-12; };
  const std::string travel = " beyond its travel " + M(axis.lower) + " .. " + M(axis.upper);
  if (!within(summary_.grasp_position)) {
    ThrowInvalidArgument("coverage: grasping '" + name + "' at coverage " + Num(request_.coverage) + " puts '" +
                         axis.id + "' at " + M(summary_.grasp_position) + "," + travel +
                         "; move the robot's base so the object is within reach");
  }
  if (!within(top)) {
    ThrowInvalidArgument("lift_height: " + Num(request_.lift_height) + " m lifts '" + axis.id + "' to " + M(top) +
                         "," + travel);
  }

  // Opening: the object's width along the pads' normal plus clearance on both sides; never closing first.
  const Vec3 extent = object.max - object.min;
  const double width = std::abs(now.normal.x()) * extent.x() + std::abs(now.normal.y()) * extent.y() +
                       std::abs(now.normal.z()) * extent.z();
  const double dgap_dq = (measure(qa0, qf0 + 0.01).gap - now.gap) / 0.01;
  const double needed = width + 2 * kOpeningClearance;
  const double opening = dgap_dq > 0 ? qf0 + (needed - now.gap) / dgap_dq : INFINITY;
  if (!(opening <= finger.upper + 1e-12)) {
    ThrowInvalidArgument("object_id: '" + name + "' is " + Mm(width) + " wide between the pads; '" + id +
                         "' opens them only " + Mm(now.gap + dgap_dq * (finger.upper - qf0)) + " apart (" +
                         Mm(kOpeningClearance) + " clearance per side needed)");
  }
  summary_.opening_position = std::max(qf0, opening);

  // A set-point the covered texels cannot read even when saturated can never be reached. A texel is covered
  // when one of its sensing elements is within the covered length from the pad's tip (pad +y).
  std::vector<bool> covered(size_t{pad0.rows} * pad0.cols, false);
  for (const PadElement& element : MakePadElements(pad0)) {
    if (length / 2 - element.position.y() < summary_.coverage * length) {
      covered[size_t{element.row} * pad0.cols + element.col] = true;
    }
  }
  const double full_scale = double(std::count(covered.begin(), covered.end(), true)) * pad0.max_intensity;
  const double covered_rows = double(std::count(covered.begin(), covered.end(), true)) / pad0.cols;
  if (request_.tactile_setpoint >= full_scale) {
    ThrowInvalidArgument("tactile_setpoint: " + Num(request_.tactile_setpoint) + " is not below the full scale " +
                         Num(full_scale) + " of the texels the object covers (" + Num(covered_rows) + " of " +
                         std::to_string(pad0.rows) + " rows x " + std::to_string(pad0.cols) + " texels x " +
                         std::to_string(pad0.max_intensity) + " at coverage " +
                         Num(std::round(summary_.coverage * 1e4) / 1e4) +
                         "); lower it or raise coverage");
  }
}

}  // namespace graspsim
