// A Scene driven by its simulation: StepSimulation's run (how many steps an amount is, chunks committed one by
// one, checkpoints) and SetActuators' settings (validated against the model, applied all or nothing). Used by
// rpc/simulation_service.cpp, which only decodes the request and encodes the result.
#pragma once

#include <chrono>
#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "physics/simulation_cache.h"
#include "world/scene.h"

namespace graspsim {

// At most this many steps in one run.
constexpr uint64_t kMaxStepsPerRun = 100'000'000;
// How much wall time of a long run a crash may lose at most: a run checkpoints its scene this often.
constexpr auto kCheckpointInterval = std::chrono::seconds(1);

// Steps per committed chunk: a snapshot every 1/60 s of simulated time (at least one step), and the scene's
// writers' lock released between chunks so that other edits are served during a long run.
uint64_t StepsPerChunk(const SimulationParams& params);

// How far a run goes: exactly one of a step count, a duration and a time to reach (s, simulated).
struct StepAmount {
  enum class Kind { kNone, kSteps, kDuration, kUntilTime };
  Kind kind = Kind::kNone;
  uint64_t steps = 0;
  double seconds = 0;  // the duration, or the time to reach

  static StepAmount Steps(uint64_t steps) { return {Kind::kSteps, steps, 0}; }
  static StepAmount Duration(double seconds) { return {Kind::kDuration, 0, seconds}; }
  static StepAmount UntilTime(double time) { return {Kind::kUntilTime, 0, time}; }
};

// The steps `amount` means for a scene at simulated `time` with steps of `time_step`. Throws
// Error(kInvalidArgument) naming the field ("duration", "until_time", "amount") for a missing or bad amount, a
// time before `time`, or more than kMaxStepsPerRun steps.
uint64_t StepsFor(const StepAmount& amount, double time, double time_step);

struct StepRunResult {
  uint64_t steps = 0;        // done: fewer than asked when cancelled
  double time = 0;           // s, the scene's simulated time after the run
  size_t contacts = 0;       // of the last step
  size_t awake_bodies = 0;   // of the last step
  uint64_t revision = 0;     // the scene's after the run
};

// Steps `scene` by `amount` on its simulation from `simulations`, in chunks of StepsPerChunk, each committed
// (Scene::Update, not journaled) with the lock released between them. `cancelled` is asked before every chunk:
// true stops the run there (the steps done so far stay). The state is checkpointed every kCheckpointInterval of
// wall time and at the end (a failure of that last one throws); a run that throws (a diverged simulation)
// checkpoints what it committed before the error propagates.
StepRunResult StepScene(Scene* scene, SimulationCache* simulations, const StepAmount& amount,
                        const std::function<bool()>& cancelled);

// One joint's drive as SetActuators asks for it.
struct ActuatorSetting {
  std::string joint_id;
  std::optional<DcMotorParams> motor;  // none: the drive of the joint's robot (physics/builtin_drives.h)
  ActuatorCommand command;             // mode kOff removes the joint's actuator
};

// Installs `settings` in the scene's state, all or nothing (validated against the model under the scene's lock).
// Errors name "<field>[i].joint_id": kNotFound for a joint the scene lacks, kInvalidArgument for a fixed or a
// mimic joint (drive its leader). Returns the scene's new revision.
uint64_t SetSceneActuators(Scene* scene, const std::vector<ActuatorSetting>& settings,
                           const std::string& field = "commands");

}  // namespace graspsim
