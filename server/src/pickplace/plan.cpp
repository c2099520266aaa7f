// Pick and place, planning: the hand on the arm, each grasp's arm configurations (pre-grasp, grasp, lifted;
// above the goal, placed, retreated) by IK within the limits and collision-free, and the arm motions between
// them (RRT-Connect for the two free-space moves, checked straight segments for the moves next to the object).
#include <algorithm>
#include <cmath>

#include "core/error.h"
#include "motion/ik.h"
#include "motion/sphere_model.h"
#include "pickplace/internal.h"

namespace graspsim::pickplace {
namespace {

// The near checkers' resolution: the straight moves pass a few millimetres from the table and the object, so
// their motion checks start with points close together (16 resolutions of travel apart, collision_checker.h).
constexpr double kNearResolution = 0.002;
// Two IK solutions belong to one straight move when no joint differs by more than this (rad): a 6–8 cm
// Cartesian move never turns a joint further, while another IK branch differs by far more.
constexpr double kSameBranch = 0.6;
// The straight moves next to the object run at this fraction of the joints' velocity limits.
constexpr double kNearSpeed = 0.15;
// The free-space moves run at this fraction (the held object must not be shaken out of the grip).
constexpr double kFreeSpeed = 0.4;

Pose Back(double d) { return {Vec3(0, 0, -d), Quat::Identity()}; }
Pose Up(const Pose& p, double d) { return {p.position + Vec3(0, 0, d), p.orientation}; }

size_t JointIndex(const SceneModel& model, const std::string& id) {
  const auto it = model.joint_index.find(id);
  if (it == model.joint_index.end()) throw Error(ErrorCode::kInternal, "hand joint '" + id + "' vanished");
  return it->second;
}

// The hand joint positions (driven, non-mimic joints) of a pre-shape and of a grasp's closed fingers.
HandJoints OpenJoints(const Setup& setup, const grasp::Preshape& preshape) {
  HandJoints out;
  for (const JointSpec& joint : setup.hand.robot.joints) {
    if (joint.type == JointType::kFixed || joint.mimic) continue;
    double value = 0;  // hand.h: joints a pre-shape does not name stay at 0
    for (const auto& [name, q] : preshape.joint_positions) {
      if (name == joint.id) value = q;
    }
    out.emplace_back(JointIndex(*setup.model, setup.arm_id + "/" + joint.id), value);
  }
  return out;
}

HandJoints ClosedJoints(const Setup& setup, const grasp::GraspSet& set, const grasp::PlannedGrasp& g) {
  HandJoints out;
  for (size_t k = 0; k < set.joint_names.size() && k < g.joints.size(); ++k) {
    const size_t index = JointIndex(*setup.model, setup.arm_id + "/" + set.joint_names[k]);
    const JointSpec& joint = setup.model->joints[index];
    if (joint.type == JointType::kFixed || joint.mimic) continue;
    out.emplace_back(index, g.joints[k]);
  }
  return out;
}

// The IK solution of `target` nearest `near` when it is on the same branch (a straight move away).
std::optional<VecX> Near(const motion::ArmModel& arm, const Pose& target, const VecX& near, uint64_t seed) {
  motion::IkOptions options;
  options.near = near;
  options.seed = seed;
  options.max_solutions = 4;
  options.restarts = 8;
  const motion::IkResult r = motion::SolveIk(arm, target, options);
  if (r.solutions.empty() || (r.solutions[0] - near).cwiseAbs().maxCoeff() > kSameBranch) return std::nullopt;
  return r.solutions[0];
}

motion::Trajectory Timed(const motion::ArmModel& arm, std::vector<VecX> waypoints, double speed) {
  const VecX velocity = arm.velocity_limits() * speed;
  return motion::Trajectory(std::move(waypoints), velocity, 2 * velocity);
}

}  // namespace

void ApplyHandJoints(const SceneModel& model, size_t robot, const HandJoints& joints, SceneState* state) {
  for (const auto& [index, q] : joints) state->joint_positions[index] = q;
  for (const size_t j : model.robot_joints[robot]) {
    const JointSpec& joint = model.joints[j];
    if (!joint.mimic) continue;
    const auto leader = model.joint_index.find(joint.mimic->joint_id);
    if (leader == model.joint_index.end()) continue;
    state->joint_positions[j] = joint.mimic->multiplier * state->joint_positions[leader->second] + joint.mimic->offset;
  }
  UpdateRobotLinkPoses(model, robot, state);
}

std::string PlaceConfigurations(const Setup& setup, const Pose& object_in_hand, GraspPlan* plan) {
  GraspPlan& p = *plan;
  const PickPlaceOptions& o = setup.options;
  const Pose hand_place = Up(setup.goal, o.place_height) * object_in_hand.Inverse();
  const Pose hand_above = Up(hand_place, o.lift);
  const Pose hand_retreat = hand_place * Back(o.standoff);
  motion::IkOptions ik;
  ik.seed = o.seed;
  p.above.clear();
  p.place.clear();
  p.retreat.clear();
  std::string why;
  const motion::IkResult above = motion::SolveIk(*p.closed_arm, hand_above, ik);
  if (above.solutions.empty()) return "unreachable: above the goal: " + above.failure;
  for (const VecX& q_above : above.solutions) {
    if (std::string e = p.closed_near->Explain(q_above); !e.empty()) {
      why = "collision above the goal: " + e;
      continue;
    }
    const std::optional<VecX> q_place = Near(*p.closed_arm, hand_place, q_above, o.seed);
    if (!q_place) {
      why = "unreachable: no straight descent to the goal";
      continue;
    }
    if (!p.closed_near->IsValid(*q_place) || !p.open_near->IsValid(*q_place) ||
        !p.closed_near->IsMotionValid(q_above, *q_place)) {
      why = "collision placing at the goal: " + p.closed_near->Explain(*q_place) + p.open_near->Explain(*q_place);
      continue;
    }
    const std::optional<VecX> q_retreat = Near(*p.open_arm, hand_retreat, *q_place, o.seed);
    if (!q_retreat || !p.open_near->IsValid(*q_retreat) || !p.open_near->IsMotionValid(*q_place, *q_retreat)) {
      why = q_retreat ? "collision on the retreat from the goal" : "unreachable: retreat from the goal";
      continue;
    }
    p.above.push_back(q_above);
    p.place.push_back(*q_place);
    p.retreat.push_back(*q_retreat);
  }
  return p.above.empty() ? why : "";
}

GraspPlan CheckGrasp(const Setup& setup, const grasp::GraspSet& set, size_t index) {
  GraspPlan p;
  p.grasp = index;
  const grasp::PlannedGrasp& g = set.grasps[index];
  const SceneModel& model = *setup.model;
  const PickPlaceOptions& o = setup.options;
  const size_t preshape = std::min<size_t>(g.candidate.preshape, setup.hand.preshapes.size() - 1);
  p.open = OpenJoints(setup, setup.hand.preshapes[preshape]);
  p.closed = ClosedJoints(setup, set, g);
  SceneState open_state = setup.state, closed_state = setup.state;
  ApplyHandJoints(model, setup.robot, p.open, &open_state);
  ApplyHandJoints(model, setup.robot, p.closed, &closed_state);
  p.open_arm = std::make_unique<motion::ArmModel>(model, open_state, setup.arm_id, setup.tip);
  p.closed_arm = std::make_unique<motion::ArmModel>(model, closed_state, setup.arm_id, setup.tip);
  const motion::ArmSphereModel open_spheres = motion::BuildSphereModel(model, *p.open_arm);
  const motion::ArmSphereModel closed_spheres = motion::BuildSphereModel(model, *p.closed_arm);
  p.open_all = std::make_unique<motion::CollisionChecker>(*p.open_arm, open_spheres, setup.all);
  p.open_near = std::make_unique<motion::CollisionChecker>(*p.open_arm, open_spheres, setup.without_object,
                                                           kNearResolution);
  p.closed_near = std::make_unique<motion::CollisionChecker>(*p.closed_arm, closed_spheres, setup.without_object,
                                                             kNearResolution);

  const Pose object = setup.state.body_poses[setup.object];
  const Pose hand_at = object * g.hand_pose * Back(o.clearance);
  const Pose hand_pre = hand_at * Back(o.standoff);
  const Pose hand_lift = Up(hand_at, o.lift);
  p.object_in_hand = hand_at.Inverse() * object;

  motion::IkOptions ik;
  ik.seed = o.seed;
  const motion::IkResult pre = motion::SolveIk(*p.open_arm, hand_pre, ik);
  if (pre.solutions.empty()) {
    p.failure = "unreachable: pre-grasp: " + pre.failure;
    return p;
  }
  std::string why;
  for (const VecX& q_pre : pre.solutions) {
    if (std::string e = p.open_all->Explain(q_pre); !e.empty()) {
      why = "collision at the pre-grasp: " + e;
      continue;
    }
    const std::optional<VecX> q_at = Near(*p.open_arm, hand_at, q_pre, o.seed);
    if (!q_at) {
      why = "unreachable: no straight approach from the pre-grasp";
      continue;
    }
    if (std::string e = p.open_near->Explain(*q_at); !e.empty()) {
      why = "collision at the grasp: " + e;
      continue;
    }
    if (std::string e = p.closed_near->Explain(*q_at); !e.empty()) {
      why = "collision at the grasp (closed): " + e;
      continue;
    }
    if (!p.open_near->IsMotionValid(q_pre, *q_at)) {
      why = "collision on the straight approach";
      continue;
    }
    const std::optional<VecX> q_lift = Near(*p.closed_arm, hand_lift, *q_at, o.seed);
    if (!q_lift) {
      why = "unreachable: lift";
      continue;
    }
    if (!p.closed_near->IsValid(*q_lift) || !p.closed_near->IsMotionValid(*q_at, *q_lift)) {
      why = "collision on the lift";
      continue;
    }
    p.pre.push_back(q_pre);
    p.at.push_back(*q_at);
  }
  if (p.pre.empty()) {
    p.failure = why;
    return p;
  }
  p.failure = PlaceConfigurations(setup, p.object_in_hand, &p);
  return p;
}

std::string PlanPlace(const Setup& setup, GraspPlan* p, const VecX& from, const std::function<bool()>& cancelled,
                      std::vector<ArmMotion>* motions) {
  motion::PlanOptions options;
  options.timeout = setup.options.plan_timeout;
  options.seed = setup.options.seed;
  options.cancelled = cancelled;
  try {
    const motion::PlanResult transfer = motion::PlanPath(*p->closed_near, from, p->above, options);
    if (transfer.cancelled) return "cancelled";
    const size_t m = transfer.goal_index;
    motions->push_back({Stage::kTransfer, Timed(*p->closed_arm, transfer.path, kFreeSpeed), true, p->closed});
    motions->push_back({Stage::kTransfer, Timed(*p->closed_arm, {p->above[m], p->place[m]}, kNearSpeed), true, p->closed});
    motions->push_back({Stage::kRetreat, Timed(*p->open_arm, {p->place[m], p->retreat[m]}, kNearSpeed), false, p->open});
    return "";
  } catch (const Error& e) {
    if (e.code() == ErrorCode::kFailedPrecondition) return std::string("no path to the goal: ") + e.what();
    throw;
  }
}

std::string PlanMotions(const Setup& setup, GraspPlan* p, const std::function<bool()>& cancelled,
                        std::vector<ArmMotion>* motions) {
  const PickPlaceOptions& o = setup.options;
  motion::PlanOptions options;
  options.timeout = o.plan_timeout;
  options.seed = o.seed;
  options.cancelled = cancelled;
  const VecX start = p->open_arm->Positions(setup.state);
  try {
    const motion::PlanResult to_pre = motion::PlanPath(*p->open_all, start, p->pre, options);
    if (to_pre.cancelled) return "cancelled";
    const size_t k = to_pre.goal_index;
    const VecX q_at = p->at[k];
    const std::optional<VecX> q_lift =
        Near(*p->closed_arm, Up(p->closed_arm->TipPose(q_at), o.lift), q_at, o.seed);
    if (!q_lift || !p->closed_near->IsMotionValid(q_at, *q_lift)) return "collision on the lift";
    p->lifted = *q_lift;
    motions->clear();
    motions->push_back({Stage::kApproach, Timed(*p->open_arm, to_pre.path, kFreeSpeed), false, p->open});
    motions->push_back({Stage::kApproach, Timed(*p->open_arm, {p->pre[k], q_at}, kNearSpeed), false, p->open});
    motions->push_back({Stage::kLift, Timed(*p->closed_arm, {q_at, *q_lift}, kNearSpeed), true, p->closed});
  } catch (const Error& e) {
    if (e.code() == ErrorCode::kFailedPrecondition) return std::string("no path to the pre-grasp: ") + e.what();
    throw;
  }
  return PlanPlace(setup, p, p->lifted, cancelled, motions);
}

}  // namespace graspsim::pickplace
