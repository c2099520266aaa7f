// Pick and place: the paper's PlanArmTrajectory (PAPERS.md part C). From a grasp set of an object, keep the
// grasps the arm can reach within its joint limits without collision, and for each of them in order of ε plan
// the whole motion (start → pre-grasp, straight approach, close, lift, transfer, straight place, release,
// retreat), execute it in the dynamic simulation on a copy of the scene state, and stop at the first one whose
// object ends at the goal. Nothing here touches a Scene: the caller commits the final state
// (PickAndPlaceInScene in scene_pick_place.h does on success only), so failed attempts leave the user's scene as it was.
//
// Frames: the hand's root link is the arm's tip (every built-in hand sits on the flange by an identity joint);
// a grasp's hand_pose is in the object frame, so the hand's world pose is object_pose · hand_pose, and at the
// goal it is goal · hand_pose.
#pragma once

#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "grasp/plan_job.h"
#include "grasp/planner.h"
#include "motion/trajectory.h"
#include "world/model.h"
#include "world/state.h"

namespace graspsim::pickplace {

using motion::VecX;

struct PickPlaceOptions {
  double standoff = 0.06;              // m back along the approach for the pre-grasp and the retreat
  double lift = 0.08;                  // m straight up (world +z) after closing; the place comes down as far
  double clearance = 0.003;            // m: the hand stops this far back from the grasp pose (no pressing)
  double place_height = 0.002;         // m above the goal the object is let go
  double position_tolerance = 0.01;    // m: success when the object ends within this of the goal …
  double orientation_tolerance = 0.17453292519943295;  // rad (10°) … and within this angle
  size_t max_attempts = 5;             // grasps executed in simulation before giving up
  double plan_timeout = 2;             // s per path search
  uint64_t seed = 1;
};

enum class Stage { kPlanGrasps, kFilter, kPlanPath, kApproach, kClose, kLift, kTransfer, kRelease, kRetreat, kDone };
const char* StageName(Stage stage);  // "planning_grasps", "filtering", "planning_path", "approach", "close",
                                     // "lift", "transfer", "release", "retreat", "done"

// Hand joint positions by scene joint index (driven joints only: mimic joints follow in ApplyHandJoints).
using HandJoints = std::vector<std::pair<size_t, double>>;

// Sets the joints and their mimic followers in *state and places the robot's links.
void ApplyHandJoints(const SceneModel& model, size_t robot, const HandJoints& joints, SceneState* state);

// One arm motion of the plan, with the hand held open or closed while it runs.
struct ArmMotion {
  Stage stage = Stage::kApproach;
  motion::Trajectory trajectory;
  bool closed = false;                 // the fingers hold the object during it
  HandJoints hand;                     // the finger positions the motion was checked with (planned, not simulated)
};

struct Attempt {
  size_t grasp = 0;                    // index into the grasp set
  std::string failure;                 // "" for the successful one
};

struct PickPlaceResult {
  bool success = false;
  bool cancelled = false;
  size_t grasp = 0;                    // the grasp that succeeded
  size_t reachable = 0;                // grasps that passed the reachability filter
  std::vector<Attempt> attempts;       // executed or planned attempts, in order
  std::vector<std::string> unreachable;  // per rejected grasp: "grasp i: why"
  std::vector<ArmMotion> motions;      // of the successful attempt (or the last one executed)
  std::vector<std::string> joint_ids;  // the arm's joints, the motions' columns
  SceneState final_state;              // the simulated state at the end of the successful attempt
  Pose object_pose;                    // where the object ended (world)
  double position_error = 0;           // m, |object − goal|
  double orientation_error = 0;        // rad
  double grip_force = 0;               // N, the hand's contact force on the object after closing
  double simulated_seconds = 0;        // s of simulated time over all attempts
};

// Called with the current stage and the job's overall fraction (0..1), at least every 50 ms of simulated time
// while executing; returning false cancels: RunPickPlace returns at once with `cancelled` set.
using Progress = std::function<bool(Stage stage, double fraction, const PickPlaceResult& so_far)>;

// The hand on `arm_id`'s flange: one of grasp::HandNames() whose root link and joints the robot has.
// Throws Error(kNotFound) for an unknown robot (naming `arm_field`), kInvalidArgument when the robot is not an
// arm with a flange, or carries no known hand.
std::string HandOnArm(const SceneModel& model, const std::string& arm_field, const std::string& arm_id);

// The grasp set PickAndPlace plans when the request names none: the object's geometry from the scene, every
// body but the arm an obstacle, bounding-box candidates on a 2 cm grid, every pre-shape, standoffs 0 and 2 cm
// (a hand whose fingers reach past the object's bottom must stop short of it to clear the table).
grasp::PlanJob DefaultGraspSetJob(const SceneModel& model, const SceneState& state, const std::string& arm_id,
                               const std::string& object_id, uint64_t seed);

// Validates the inputs (errors name the fields) and runs. Throws Error(kFailedPrecondition) when no grasp is
// reachable or every attempt failed (the message lists the reasons).
// `model` must be the model `state` belongs to.
PickPlaceResult RunPickPlace(std::shared_ptr<const SceneModel> model, const SceneState& state,
                             const std::string& arm_id, const std::string& object_id, const Pose& goal,
                             const grasp::GraspSet& set, const PickPlaceOptions& options, const Progress& progress);

}  // namespace graspsim::pickplace
