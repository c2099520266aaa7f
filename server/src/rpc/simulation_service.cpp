// SceneService's simulation methods: parameters, actuators, stepping.
#include <chrono>
#include <cmath>

#include "core/error.h"
#include "core/format.h"
#include "core/validate.h"
#include "physics/builtin_drives.h"
#include "rpc/call.h"
#include "rpc/convert.h"
#include "rpc/scene_edits.h"
#include "rpc/scene_service.h"

namespace graspsim::rpc {
namespace {

// Steps per committed chunk: a snapshot every 1/60 s of simulated time, and the scene's writers' lock released
// between chunks so that other edits are served during a long run (readers never wait for a chunk: world/scene.h).
uint64_t StepsPerChunk(const SimulationParams& params) {
  return std::max<uint64_t>(1, static_cast<uint64_t>(std::lround((1.0 / 60) / params.time_step)));
}

constexpr uint64_t kMaxStepsPerRequest = 100'000'000;

// How much wall time of a long run a crash may lose at most.
constexpr auto kCheckpointInterval = std::chrono::seconds(1);

// Stores the simulated state when a run ends by an error (divergence, a failed chunk); the success path
// checkpoints itself, so that a failed write fails the request.
class CheckpointOnExit {
 public:
  explicit CheckpointOnExit(Scene* scene) : scene_(scene) {}
  ~CheckpointOnExit() {
    try {
      scene_->Checkpoint();
    } catch (const std::exception&) {  // the request already fails with its own error
    }
  }

 private:
  Scene* scene_;
};

}  // namespace

grpc::ServerUnaryReactor* SceneServiceImpl::SetSimulationParams(grpc::CallbackServerContext* context,
                                                                const v1::SetSimulationParamsRequest* request,
                                                                v1::SimulationParams* response) {
  return RunUnary(context, "SetSimulationParams", pool_, [=, this] {
    SetSimulationParamsFromRequest(registry_->Get(request->scene_id()).get(), *request, response);
  });
}

grpc::ServerUnaryReactor* SceneServiceImpl::GetSimulationParams(grpc::CallbackServerContext* context,
                                                                const v1::GetSimulationParamsRequest* request,
                                                                v1::SimulationParams* response) {
  return RunUnary(context, "GetSimulationParams", pool_, [=, this] {
    ToProto(registry_->Get(request->scene_id())->View().model->simulation, response);
  });
}

grpc::ServerUnaryReactor* SceneServiceImpl::SetActuators(grpc::CallbackServerContext* context,
                                                         const v1::SetActuatorsRequest* request,
                                                         v1::SetActuatorsResponse*) {
  return RunUnary(context, "SetActuators", pool_, [=, this] {
    auto scene = registry_->Get(request->scene_id());
    scene->Update([&](const std::shared_ptr<const SceneModel>& model, SceneState* state) {
      // Validated against the model under the lock, applied to the copy: all or nothing.
      for (int i = 0; i < request->commands_size(); ++i) {
        const std::string field = "commands[" + std::to_string(i) + "]";
        const auto& command = request->commands(i);
        const auto found = model->joint_index.find(command.joint_id());
        if (found == model->joint_index.end()) {
          ThrowNotFound(field + ".joint_id: no joint '" + command.joint_id() + "' in scene '" + scene->id() + "'");
        }
        const JointSpec& joint = model->joints[found->second];
        if (joint.type == JointType::kFixed || joint.mimic) {
          ThrowInvalidArgument(field + ".joint_id: '" + joint.id + "' is " +
                               (joint.mimic ? "a mimic joint; drive its leader" : "a fixed joint"));
        }
        if (command.mode() == v1::ACTUATOR_MODE_OFF) {
          state->actuators.erase(found->second);
          continue;
        }
        // A joint without its own motor settings gets its robot's drive (physics/builtin_drives.h): the PG70's for
        // the built-in PG70s' fingers, the axis drive for the z axis.
        const RobotSpec& robot = model->robots[model->robot_index.at(joint.robot_id)];
        JointActuator& actuator = state->actuators[found->second];
        actuator.motor = command.has_motor() ? DcMotorFromProto(field + ".motor", command.motor())
                                             : BuiltinDrive(robot, joint);
        actuator.command = ActuatorCommandFromProto(field, command);
      }
    });
  });
}

grpc::ServerUnaryReactor* SceneServiceImpl::StepSimulation(grpc::CallbackServerContext* context,
                                                           const v1::StepSimulationRequest* request,
                                                           v1::StepSimulationResponse* response) {
  return RunUnary(context, "StepSimulation", pool_, [=, this] {
    auto scene = registry_->Get(request->scene_id());
    const SceneView view = scene->View();
    const double dt = view.model->simulation.time_step;
    uint64_t steps = 0;
    switch (request->amount_case()) {
      case v1::StepSimulationRequest::kSteps:
        steps = request->steps();
        break;
      case v1::StepSimulationRequest::kDuration:
        CheckPositive("duration", request->duration());
        steps = static_cast<uint64_t>(std::llround(std::min(request->duration() / dt, 1e12)));
        break;
      case v1::StepSimulationRequest::kUntilTime:
        CheckFinite("until_time", request->until_time());
        if (request->until_time() < view.state.time) {
          ThrowInvalidArgument("until_time: " + FormatNumber(request->until_time()) +
                               " s is before the scene's time " + FormatNumber(view.state.time) + " s");
        }
        steps = static_cast<uint64_t>(std::llround(std::min((request->until_time() - view.state.time) / dt, 1e12)));
        break;
      case v1::StepSimulationRequest::AMOUNT_NOT_SET:
        ThrowInvalidArgument("amount: give steps, duration or until_time");
    }
    if (steps > kMaxStepsPerRequest) {
      ThrowInvalidArgument("amount: " + std::to_string(steps) + " steps in one request, at most " +
                           std::to_string(kMaxStepsPerRequest));
    }
    StepStats stats;
    uint64_t done = 0;
    // Chunks are not journaled one by one: the state is stored once at the end, before the reply, and every
    // kCheckpointInterval of a long run (docs/durability.md). A run that fails stores what it committed.
    CheckpointOnExit checkpoint(scene.get());
    auto last_checkpoint = std::chrono::steady_clock::now();
    while (done < steps) {
      if (context->IsCancelled()) break;  // the caller gave up (or its deadline passed): stop between chunks
      const uint64_t chunk = std::min(steps - done, StepsPerChunk(view.model->simulation));
      const uint64_t revision = scene->Update(
          [&](const std::shared_ptr<const SceneModel>& model, SceneState* state) {
            stats = simulations_->For(scene->id(), model)->Step(state, static_cast<int>(chunk));
          },
          /*journal=*/false);
      response->set_revision(revision);
      done += chunk;
      if (std::chrono::steady_clock::now() - last_checkpoint > kCheckpointInterval) {
        scene->Checkpoint();
        last_checkpoint = std::chrono::steady_clock::now();
      }
    }
    scene->Checkpoint();  // durable before the reply; a failure here fails the request
    const SceneView after = scene->View();
    response->set_time(after.state.time);
    response->set_steps(done);
    response->set_contacts(stats.contacts);
    response->set_awake_bodies(stats.awake_bodies);
    response->set_revision(after.revision);
  });
}

}  // namespace graspsim::rpc
