// Pick and place internals shared by plan.cpp (configurations and paths) and execute.cpp (the simulation).
#pragma once

#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "grasp/hand.h"
#include "motion/collision_checker.h"
#include "motion/planner.h"
#include "pickplace/pick_place.h"

namespace graspsim::pickplace {

// Everything fixed for one request: the arm, the hand, the object and the obstacles.
struct Setup {
  std::shared_ptr<const SceneModel> model;
  SceneState state;                    // the start
  std::string arm_id, object_id, tip;  // tip: the hand's root body
  size_t robot = 0, object = 0;
  grasp::HandSpec hand;
  Pose goal;
  PickPlaceOptions options;
  motion::Obstacles all, without_object;  // every body not of the arm; the same less the object
};

// The configurations of one grasp: reachable within the limits and collision-free (else `failure`).
struct GraspPlan {
  size_t grasp = 0;
  std::string failure;
  HandJoints open, closed;
  // The arm for the open and the closed hand (held finger positions differ) and their checkers: near ones
  // (resolution 2 mm, for the straight moves next to the object and the table) and a free-space one.
  std::unique_ptr<motion::ArmModel> open_arm, closed_arm;
  std::unique_ptr<motion::CollisionChecker> open_all, open_near, closed_near;
  std::vector<VecX> pre, at;           // matching pairs: pre-grasp, grasp
  VecX lifted;                         // after the lift, for the pair the path chose (PlanMotions)
  std::vector<VecX> above, place, retreat;  // matching triples at the goal
  Pose object_in_hand;                 // the object's pose in the hand frame while held, as planned
};

// Filters one grasp (IK, limits, collisions); never throws for an unreachable grasp.
GraspPlan CheckGrasp(const Setup& setup, const grasp::GraspSet& set, size_t index);

// The configurations above the goal, at it and retreated (plan->above, place, retreat) for the object held at
// `object_in_hand`; returns "" or why there are none.
std::string PlaceConfigurations(const Setup& setup, const Pose& object_in_hand, GraspPlan* plan);

// Plans the arm motions of a reachable grasp (to the pre-grasp, approach, lift, then PlanPlace's); returns "" or
// why it failed.
std::string PlanMotions(const Setup& setup, GraspPlan* plan, const std::function<bool()>& cancelled,
                        std::vector<ArmMotion>* motions);
// Appends transfer (from `from` to above the goal), place and retreat.
std::string PlanPlace(const Setup& setup, GraspPlan* plan, const VecX& from, const std::function<bool()>& cancelled,
                      std::vector<ArmMotion>* motions);

// After the lift: the object's measured pose in the hand and the arm's configuration; returns "" and the motions
// that replace the planned transfer, place and retreat, or why there are none.
using Replan = std::function<std::string(const Pose& object_in_hand, const VecX& q, std::vector<ArmMotion>* rest)>;

// Executes the motions in a simulation of setup.model from setup.state; returns "" or why it failed
// (slipped, dropped, missed the goal); fills the result's motions (as executed), state, object pose and errors.
std::string Execute(const Setup& setup, const GraspPlan& plan, const std::vector<ArmMotion>& motions,
                    const Replan& replan, const Progress& progress, double fraction_begin, double fraction_end,
                    PickPlaceResult* result);

}  // namespace graspsim::pickplace
