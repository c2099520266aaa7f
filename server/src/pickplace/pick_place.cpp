// Pick and place, the loop: validate, filter the grasp set by reachability, then plan and execute the grasps in
// order of ε until one puts the object at the goal.
#include "pickplace/pick_place.h"

#include <cmath>

#include "core/error.h"
#include "core/format.h"
#include "core/validate.h"
#include "grasp/scene_object.h"
#include "pickplace/internal.h"

namespace graspsim::pickplace {
namespace {

// The filter looks at this many grasps at most (the best by ε): enough for every set the planner keeps by default
// (50), and a bound on the IK work a huge set would cost.
constexpr size_t kMaxFiltered = 64;
// Reasons kept per kind of failure in the error message.
constexpr size_t kReasonsShown = 3;

std::string Summary(const std::vector<std::string>& reasons) {
  std::string out;
  for (size_t i = 0; i < reasons.size() && i < kReasonsShown; ++i) out += (i ? "; " : "") + reasons[i];
  if (reasons.size() > kReasonsShown) out += "; … (" + std::to_string(reasons.size()) + " in all)";
  return out;
}

}  // namespace

const char* StageName(Stage stage) {
  switch (stage) {
    case Stage::kPlanGrasps: return "planning_grasps";
    case Stage::kFilter: return "filtering";
    case Stage::kPlanPath: return "planning_path";
    case Stage::kApproach: return "approach";
    case Stage::kClose: return "close";
    case Stage::kLift: return "lift";
    case Stage::kTransfer: return "transfer";
    case Stage::kRelease: return "release";
    case Stage::kRetreat: return "retreat";
    case Stage::kDone: return "done";
  }
  return "?";
}

std::string HandOnArm(const SceneModel& model, const std::string& arm_field, const std::string& arm_id) {
  const auto robot = model.robot_index.find(arm_id);
  if (robot == model.robot_index.end()) ThrowNotFound(arm_field + ": no robot '" + arm_id + "' in the scene");
  if (!model.body_index.contains(arm_id + "/flange")) {
    ThrowInvalidArgument(arm_field + ": robot '" + arm_id + "' is not an arm (it has no 'flange' link)");
  }
  for (const std::string& name : grasp::HandNames()) {
    const grasp::HandSpec hand = grasp::LoadHand("hand_id", name);
    bool all = model.body_index.contains(arm_id + "/" + hand.robot.root_link);
    for (const JointSpec& joint : hand.robot.joints) all = all && model.joint_index.contains(arm_id + "/" + joint.id);
    if (all) return name;
  }
  std::string known;
  for (const std::string& name : grasp::HandNames()) known += (known.empty() ? "" : ", ") + name;
  ThrowInvalidArgument(arm_field + ": arm '" + arm_id + "' carries no known hand on its flange (known: " + known + ")");
}

GraspSetJob DefaultGraspSetJob(const SceneModel& model, const SceneState& state, const std::string& arm_id,
                               const std::string& object_id, uint64_t seed) {
  GraspSetJob job;
  job.hand = HandOnArm(model, "arm_id", arm_id);
  grasp::SceneObject object = grasp::ObjectFromScene(model, state, "body_id", object_id, {arm_id});
  job.mesh = std::move(object.mesh);
  job.obstacles = std::move(object.obstacles);
  const grasp::HandSpec hand = grasp::LoadHand("hand_id", job.hand);
  job.candidates.preshapes.clear();
  for (uint32_t i = 0; i < hand.preshapes.size(); ++i) job.candidates.preshapes.push_back(i);
  job.candidates.standoffs = {0.0, 0.02};
  job.candidates.seed = seed;
  return job;
}

PickPlaceResult RunPickPlace(std::shared_ptr<const SceneModel> model, const SceneState& state,
                             const std::string& arm_id, const std::string& object_id, const Pose& goal,
                             const grasp::GraspSet& set, const PickPlaceOptions& options, const Progress& progress) {
  Setup setup;
  setup.hand = grasp::LoadHand("hand_id", HandOnArm(*model, "arm_id", arm_id));
  if (set.hand != setup.hand.name) {
    ThrowInvalidArgument("grasp_set_id: the set is for hand '" + set.hand + "', arm '" + arm_id + "' carries '" +
                         setup.hand.name + "'");
  }
  const auto object = model->body_index.find(object_id);
  if (object == model->body_index.end()) ThrowNotFound("body_id: no body '" + object_id + "' in the scene");
  if (model->bodies[object->second].motion != BodyMotion::kFree) {
    ThrowInvalidArgument("body_id: '" + object_id + "' is not a free body; pick-and-place moves a free object");
  }
  CheckFinite("goal.position", goal.position);
  setup.model = model;
  setup.state = state;
  setup.arm_id = arm_id;
  setup.object_id = object_id;
  setup.tip = arm_id + "/" + setup.hand.robot.root_link;
  setup.robot = model->robot_index.at(arm_id);
  setup.object = object->second;
  setup.goal = goal;
  setup.options = options;
  setup.all = motion::CollectObstacles(*model, state, arm_id);
  setup.without_object = motion::CollectObstacles(*model, state, arm_id, {object_id});

  PickPlaceResult result;
  const auto cancelled = [&] { return progress && !progress(Stage::kPlanPath, 0.1, result) ; };
  // Filter: 0 .. 0.1 of the job.
  std::vector<GraspPlan> reachable;
  const size_t n = std::min(set.grasps.size(), kMaxFiltered);
  for (size_t i = 0; i < n; ++i) {
    if (progress && !progress(Stage::kFilter, 0.1 * i / std::max<size_t>(n, 1), result)) {
      result.cancelled = true;
      return result;
    }
    GraspPlan plan = CheckGrasp(setup, set, i);
    if (plan.failure.empty()) {
      reachable.push_back(std::move(plan));
    } else {
      result.unreachable.push_back("grasp " + std::to_string(i) + ": " + plan.failure);
    }
  }
  result.reachable = reachable.size();
  if (reachable.empty()) {
    throw Error(ErrorCode::kFailedPrecondition,
                "no grasp of the " + std::to_string(set.grasps.size()) + " in the set is reachable and collision-free "
                "(unreachable or collision): " + (n == 0 ? std::string("the set is empty") : Summary(result.unreachable)));
  }
  const size_t attempts = std::min(reachable.size(), std::max<size_t>(options.max_attempts, 1));
  std::vector<std::string> failures;
  for (size_t a = 0; a < attempts; ++a) {
    GraspPlan& plan = reachable[a];
    const double f0 = 0.1 + 0.9 * a / attempts, f1 = 0.1 + 0.9 * (a + 1) / attempts;
    if (progress && !progress(Stage::kPlanPath, f0, result)) {
      result.cancelled = true;
      return result;
    }
    std::vector<ArmMotion> motions;
    std::string failure = PlanMotions(setup, &plan, [&] { return cancelled(); }, &motions);
    if (failure == "cancelled") {
      result.cancelled = true;
      return result;
    }
    if (failure.empty()) {
      result.joint_ids = plan.open_arm->joint_ids();
      result.motions = motions;
      failure = Execute(setup, plan, motions, progress, f0, f1, &result);
      if (failure == "cancelled") {
        result.cancelled = true;
        return result;
      }
    }
    result.attempts.push_back({plan.grasp, failure});
    if (failure.empty()) {
      result.success = true;
      result.grasp = plan.grasp;
      return result;
    }
    failures.push_back("grasp " + std::to_string(plan.grasp) + ": " + failure);
  }
  throw Error(ErrorCode::kFailedPrecondition,
              "every attempted grasp failed (" + std::to_string(attempts) + " of " + std::to_string(reachable.size()) +
                  " reachable): " + Summary(failures));
}

}  // namespace graspsim::pickplace
