#include "physics/scene_stepping.h"

#include <algorithm>
#include <cmath>

#include "core/error.h"
#include "core/format.h"
#include "core/validate.h"
#include "physics/builtin_drives.h"

namespace graspsim {
namespace {

// Stores the simulated state when a run ends by an error (divergence, a failed chunk); the success path
// checkpoints itself, so that a failed write fails the run.
class CheckpointOnExit {
 public:
  explicit CheckpointOnExit(Scene* scene) : scene_(scene) {}
  ~CheckpointOnExit() {
    try {
      scene_->Checkpoint();
    } catch (const std::exception&) {  // the run already fails with its own error
    }
  }

 private:
  Scene* scene_;
};

uint64_t StepsOf(double seconds) { return static_cast<uint64_t>(std::llround(std::min(seconds, 1e12))); }

}  // namespace

uint64_t StepsPerChunk(const SimulationParams& params) {
  return std::max<uint64_t>(1, static_cast<uint64_t>(std::lround((1.0 / 60) / params.time_step)));
}

uint64_t StepsFor(const StepAmount& amount, double time, double time_step) {
  uint64_t steps = 0;
  switch (amount.kind) {
    case StepAmount::Kind::kSteps:
      steps = amount.steps;
      break;
    case StepAmount::Kind::kDuration:
      CheckPositive("duration", amount.seconds);
      steps = StepsOf(amount.seconds / time_step);
      break;
    case StepAmount::Kind::kUntilTime:
      CheckFinite("until_time", amount.seconds);
      if (amount.seconds < time) {
        ThrowInvalidArgument("until_time: " + FormatNumber(amount.seconds) + " s is before the scene's time " +
                             FormatNumber(time) + " s");
      }
      steps = StepsOf((amount.seconds - time) / time_step);
      break;
    case StepAmount::Kind::kNone:
      ThrowInvalidArgument("amount: give steps, duration or until_time");
  }
  if (steps > kMaxStepsPerRun) {
    ThrowInvalidArgument("amount: " + std::to_string(steps) + " steps in one request, at most " +
                         std::to_string(kMaxStepsPerRun));
  }
  return steps;
}

StepRunResult StepScene(Scene* scene, SimulationCache* simulations, const StepAmount& amount,
                        const std::function<bool()>& cancelled) {
  const SceneView view = scene->View();
  const uint64_t steps = StepsFor(amount, view.state.time, view.model->simulation.time_step);
  StepStats stats;
  uint64_t done = 0;
  // Chunks are not journaled one by one: the state is stored once at the end, before the reply, and every
  // kCheckpointInterval of a long run (docs/durability.md). A run that fails stores what it committed.
  CheckpointOnExit checkpoint(scene);
  auto last_checkpoint = std::chrono::steady_clock::now();
  while (done < steps) {
    if (cancelled && cancelled()) break;  // the caller gave up (or its deadline passed): stop between chunks
    const uint64_t chunk = std::min(steps - done, StepsPerChunk(view.model->simulation));
    scene->Update(
        [&](const std::shared_ptr<const SceneModel>& model, SceneState* state) {
          stats = simulations->For(scene->id(), model)->Step(state, static_cast<int>(chunk));
        },
        /*journal=*/false);
    done += chunk;
    if (std::chrono::steady_clock::now() - last_checkpoint > kCheckpointInterval) {
      scene->Checkpoint();
      last_checkpoint = std::chrono::steady_clock::now();
    }
  }
  scene->Checkpoint();  // durable before the reply; a failure here fails the run
  const SceneView after = scene->View();
  return {done, after.state.time, stats.contacts, stats.awake_bodies, after.revision};
}

uint64_t SetSceneActuators(Scene* scene, const std::vector<ActuatorSetting>& settings, const std::string& field) {
  return scene->Update([&](const std::shared_ptr<const SceneModel>& model, SceneState* state) {
    // Validated against the model under the lock, applied to the copy: all or nothing.
    for (size_t i = 0; i < settings.size(); ++i) {
      const std::string at = field + "[" + std::to_string(i) + "]";
      const ActuatorSetting& setting = settings[i];
      const auto found = model->joint_index.find(setting.joint_id);
      if (found == model->joint_index.end()) {
        ThrowNotFound(at + ".joint_id: no joint '" + setting.joint_id + "' in scene '" + scene->id() + "'");
      }
      const JointSpec& joint = model->joints[found->second];
      if (joint.type == JointType::kFixed || joint.mimic) {
        ThrowInvalidArgument(at + ".joint_id: '" + joint.id + "' is " +
                             (joint.mimic ? "a mimic joint; drive its leader" : "a fixed joint"));
      }
      if (setting.command.mode == ActuatorMode::kOff) {
        state->actuators.erase(found->second);
        continue;
      }
      // A joint without its own motor settings gets its robot's drive (builtin_drives.h): the PG70's for the
      // built-in PG70s' fingers, the axis drive for the z axis.
      const RobotSpec& robot = model->robots[model->robot_index.at(joint.robot_id)];
      JointActuator& actuator = state->actuators[found->second];
      actuator.motor = setting.motor ? *setting.motor : BuiltinDrive(robot, joint);
      actuator.command = setting.command;
    }
  });
}

}  // namespace graspsim
