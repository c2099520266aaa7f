// Pick and place, the loop: validate, filter the grasp set by reachability, then plan and execute the grasps in
// order of ε until one puts the object at the goal.
#include "pickplace/pick_place.h"

#include <algorithm>
#include <cmath>
#include <tuple>

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

// Reasons grouped by kind (the text up to its second colon: "collision at the pre-grasp", "unreachable: above
// the goal"), each with its count and its first full text, most frequent first.
std::string Summary(const std::vector<std::pair<size_t, std::string>>& reasons) {
  std::vector<std::tuple<std::string, size_t, std::string>> kinds;  // kind, count, example
  for (const auto& [grasp, text] : reasons) {
    size_t cut = text.find(": ");
    if (cut != std::string::npos && text.compare(0, 11, "unreachable") == 0) cut = text.find(": ", cut + 2);
    const std::string kind = text.substr(0, cut);
    auto it = std::find_if(kinds.begin(), kinds.end(), [&](const auto& k) { return std::get<0>(k) == kind; });
    if (it == kinds.end()) {
      kinds.emplace_back(kind, 1, "grasp " + std::to_string(grasp) + ": " + text);
    } else {
      ++std::get<1>(*it);
    }
  }
  std::stable_sort(kinds.begin(), kinds.end(), [](const auto& a, const auto& b) { return std::get<1>(a) > std::get<1>(b); });
  std::string out;
  for (size_t i = 0; i < kinds.size() && i < kReasonsShown; ++i) {
    out += (i ? "; " : "") + std::to_string(std::get<1>(kinds[i])) + " × " + std::get<0>(kinds[i]) + " (e.g. " +
           std::get<2>(kinds[i]) + ")";
  }
  if (kinds.size() > kReasonsShown) out += "; and " + std::to_string(kinds.size() - kReasonsShown) + " other kinds";
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

grasp::PlanJob DefaultGraspSetJob(const SceneModel& model, const SceneState& state, const std::string& arm_id,
                               const std::string& object_id, uint64_t seed) {
  grasp::PlanJob job;
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
  // Every report goes through here; the path searches poll `cancelled`, which repeats the last report.
  Stage last_stage = Stage::kFilter;
  double last_fraction = 0;
  const Progress report = [&](Stage stage, double fraction, const PickPlaceResult& so_far) {
    last_stage = stage;
    last_fraction = fraction;
    return !progress || progress(stage, fraction, so_far);
  };
  const auto cancelled = [&] { return !report(last_stage, last_fraction, result); };
  // Filter: 0 .. 0.1 of the job.
  std::vector<GraspPlan> reachable;
  std::vector<std::pair<size_t, std::string>> rejected, failures;
  const size_t n = std::min(set.grasps.size(), kMaxFiltered);
  for (size_t i = 0; i < n; ++i) {
    if (!report(Stage::kFilter, 0.1 * i / std::max<size_t>(n, 1), result)) {
      result.cancelled = true;
      return result;
    }
    GraspPlan plan = CheckGrasp(setup, set, i);
    if (plan.failure.empty()) {
      reachable.push_back(std::move(plan));
    } else {
      result.unreachable.push_back("grasp " + std::to_string(i) + ": " + plan.failure);
      rejected.emplace_back(i, plan.failure);
    }
  }
  result.reachable = reachable.size();
  if (reachable.empty()) {
    throw Error(ErrorCode::kFailedPrecondition,
                "no grasp of the " + std::to_string(set.grasps.size()) + " in the set is reachable and collision-free "
                "(unreachable or collision): " + (n == 0 ? std::string("the set is empty") : Summary(rejected)));
  }
  const size_t attempts = std::min(reachable.size(), std::max<size_t>(options.max_attempts, 1));
  for (size_t a = 0; a < attempts; ++a) {
    GraspPlan& plan = reachable[a];
    const double f0 = 0.1 + 0.9 * a / attempts, f1 = 0.1 + 0.9 * (a + 1) / attempts;
    if (!report(Stage::kPlanPath, f0, result)) {
      result.cancelled = true;
      return result;
    }
    std::vector<ArmMotion> motions;
    std::string failure = PlanMotions(setup, &plan, cancelled, &motions);
    if (failure == "cancelled") {
      result.cancelled = true;
      return result;
    }
    if (failure.empty()) {
      result.joint_ids = plan.open_arm->joint_ids();
      const Replan replan = [&](const Pose& in_hand, const VecX& q, std::vector<ArmMotion>* rest) {
        if (std::string why = PlaceConfigurations(setup, in_hand, &plan); !why.empty()) return "as gripped: " + why;
        return PlanPlace(setup, &plan, q, cancelled, rest);
      };
      failure = Execute(setup, plan, motions, replan, report, f0, f1, &result);
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
    failures.emplace_back(plan.grasp, failure);
  }
  throw Error(ErrorCode::kFailedPrecondition,
              "every attempted grasp failed (" + std::to_string(attempts) + " of " + std::to_string(reachable.size()) +
                  " reachable): " + Summary(failures));
}

}  // namespace graspsim::pickplace
