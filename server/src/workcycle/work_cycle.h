// The grasp work cycle of PAPERS.md part B (experiment 3): a parallel gripper carried by a vertical axis picks
// an object up and puts it back, with the paper's tactile force control.
//
// Stages (each a state of WorkCycle, advanced one simulation step at a time):
//   approach   fingers open (position mode) to the object's width plus clearance; then the z axis (position
//              mode, a trapezoidal set-point) lowers the gripper to the grasp height given by `coverage`
//   grasp      fingers close in velocity mode until the first tactile contact; from then on force control:
//              every control period a PI on the pads' mean intensity sum sets the finger drive's current limit
//              (the velocity command stays "closing", so the limit is the gripping force); the stage ends when
//              the sum stays within 5 % of the set-point for 0.2 s (or after a timeout)
//   lift       the axis lifts by lift_height, force control on
//   hold       hold_time at the top
//   move_down  back to the grasp height
//   release    the fingers open until both pads read zero
//   done
// The controller samples the sensors and decides every control period (10 ms, the DSACON32's order of frame
// rate); the axis's set-point is updated every step. Readings go out as frames at frame_rate_hz of simulated
// time, and at the first step of each stage. The drives are the joints' installed motors if any, else the
// built-in drives (physics/builtin_drives.h). docs/tactile.md has the parameters and the measured figures.
#pragma once

#include <array>
#include <cstdint>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "physics/simulation.h"
#include "sensors/readings.h"
#include "tactile/tactile_frame.h"
#include "world/model.h"
#include "world/state.h"

namespace graspsim {

struct WorkCycleRequest {
  std::string gripper_id;         // a robot with joints "<id>/z_axis", "<id>/finger_left_joint", two pads
  std::string object_id;          // a free body resting below the gripper
  double tactile_setpoint = 60000;  // intensity sum per pad
  double lift_height = 0.05;      // m
  double coverage = 1;            // fraction of the pads' length on the object, (0, 1]
  double frame_rate_hz = 50;      // frames per simulated second, at most one per step
  double hold_time = 1;           // s
};

enum class WorkCycleStage { kApproach, kGrasp, kLift, kHold, kMoveDown, kRelease, kDone };
const char* StageName(WorkCycleStage stage);  // "approach", ..., "move_down", "release", "done"

struct WorkCycleFrame {
  WorkCycleStage stage = WorkCycleStage::kApproach;
  double time = 0;                      // s, simulation
  std::array<TactileFrame, 2> pads;     // in the robot's tactile_array_ids order
  GripperReading gripper;
  Pose object_pose;                     // world
  double axis_position = 0;             // m
  double current_limit = 0;             // A: the force controller's output, the drive's own limit otherwise
};

// What the controller planned and what happened, for tests and reports. Times are simulation times, s.
struct WorkCycleSummary {
  double grasp_position = 0;            // m, z axis at the grasp height
  double coverage = 0;                  // the coverage used: the requested one, or less where the clamp held
  double opening_position = 0;          // m, finger joint position the fingers open to
  double first_contact_time = std::numeric_limits<double>::quiet_NaN();
  bool settled = false;                 // the grasp reached the set-point band (else it timed out)
  std::array<double, 7> stage_start{};  // by WorkCycleStage
};

class WorkCycle {
 public:
  // Validates the request against the scene (errors name the field and the value) and plans the grasp height.
  // The state is the scene's current state; it is not changed.
  WorkCycle(std::shared_ptr<const SceneModel> model, const SceneState& state, const WorkCycleRequest& request);

  // Runs at most `max_steps` steps of `simulation` (which must be for this cycle's model) on *state, appending
  // the frames that fall due (and one per stage change); returns the steps taken. The first call installs the
  // drives and emits the frame at the start time; the last emits the "done" frame. Throws
  // Error(kFailedPrecondition) when a stage cannot finish (something blocks the axis, the fingers close on
  // nothing) or the scene's model changed, and any simulation error; *state then holds the last completed step.
  // Chunking does not matter: any split of the same run gives bit-identical frames.
  uint64_t Advance(PhysicsEngine* simulation, SceneState* state, uint64_t max_steps,
                   std::vector<WorkCycleFrame>* frames);

  bool done() const { return finished_; }
  WorkCycleStage stage() const { return stage_; }
  const WorkCycleSummary& summary() const { return summary_; }
  const std::array<std::string, 2>& pad_ids() const { return pad_ids_; }
  const std::string& gripper_id() const { return request_.gripper_id; }

 private:
  // A trapezoidal move of the axis's set-point (triangular when short).
  struct Move {
    double from = 0, to = 0, start = 0, speed = 1, acceleration = 1;
    double Duration() const;
    double At(double time) const;
  };

  void Plan(const SceneState& state);
  void Start(SceneState* state);
  bool Touching(const SceneState& state) const;
  // The intensity sum of pad `pad` (index into pads_), read into a reused frame.
  uint64_t IntensitySum(const SceneState& state, size_t pad) const;
  // Whether the next step must record the sensors' readings (PhysicsEngine::Readings).
  bool ReadingsWanted(const SceneState& state, bool last_of_call) const;
  double NextFrameTime() const;  // s: when the next frame on the frame-rate grid is due
  void Control(SceneState* state);
  void Enter(WorkCycleStage stage, SceneState* state);
  void ForceControl(SceneState* state, double mean_sum);
  bool MoveFinished(const SceneState& state) const;
  void SetCommand(SceneState* state, size_t joint, ActuatorMode mode, double value, double current_limit) const;
  WorkCycleFrame Frame(const SceneState& state) const;

  std::shared_ptr<const SceneModel> model_;
  WorkCycleRequest request_;
  WorkCycleSummary summary_;
  std::array<std::string, 2> pad_ids_;
  std::array<size_t, 2> pads_{};
  mutable TactileFrame pad_reading_;  // IntensitySum's buffers
  size_t robot_ = 0, axis_ = 0, finger_ = 0, object_ = 0;
  DcMotorParams axis_drive_, finger_drive_;
  double lift_position_ = 0;     // m of axis travel that lifts by lift_height
  double amps_per_count_ = 0;    // A per intensity count on one pad: 1 / (intensity_per_newton · pad N/A)
  double current_cap_ = 0;       // A, the force controller's largest output
  double dt_ = 1e-3;
  uint64_t control_steps_ = 10, steps_ = 0, next_control_ = 0;
  double start_time_ = 0;        // s: frames are due at start_time_ + k / frame_rate_hz
  uint64_t frames_due_ = 0;      // k of the next one

  WorkCycleStage stage_ = WorkCycleStage::kApproach;
  bool started_ = false, finished_ = false;
  bool descending_ = false, force_control_ = false;
  Move move_;
  double stage_start_ = 0, band_since_ = -1;
  double current_limit_ = 0;     // A, the controller's output
  double integral_ = 0;          // A, the PI's integral part
};

}  // namespace graspsim
