// SceneService's simulation methods: parameters, actuators, stepping (the run itself: physics/scene_stepping.h).
#include "physics/scene_stepping.h"
#include "rpc/call.h"
#include "rpc/convert.h"
#include "rpc/scene_edits.h"
#include "rpc/scene_service.h"

namespace graspsim::rpc {

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
    const std::shared_ptr<Scene> scene = registry_->Get(request->scene_id());
    std::vector<ActuatorSetting> settings(request->commands_size());
    for (int i = 0; i < request->commands_size(); ++i) {
      const std::string field = "commands[" + std::to_string(i) + "]";
      const v1::ActuatorCommand& command = request->commands(i);
      settings[i].joint_id = command.joint_id();
      if (command.has_motor()) settings[i].motor = DcMotorFromProto(field + ".motor", command.motor());
      settings[i].command = ActuatorCommandFromProto(field, command);
    }
    SetSceneActuators(scene.get(), settings);
  });
}

grpc::ServerUnaryReactor* SceneServiceImpl::StepSimulation(grpc::CallbackServerContext* context,
                                                           const v1::StepSimulationRequest* request,
                                                           v1::StepSimulationResponse* response) {
  return RunUnary(context, "StepSimulation", pool_, [=, this] {
    StepAmount amount;
    switch (request->amount_case()) {
      case v1::StepSimulationRequest::kSteps: amount = StepAmount::Steps(request->steps()); break;
      case v1::StepSimulationRequest::kDuration: amount = StepAmount::Duration(request->duration()); break;
      case v1::StepSimulationRequest::kUntilTime: amount = StepAmount::UntilTime(request->until_time()); break;
      case v1::StepSimulationRequest::AMOUNT_NOT_SET: break;
    }
    const StepRunResult result = StepScene(registry_->Get(request->scene_id()).get(), simulations_, amount,
                                           [context] { return context->IsCancelled(); });
    response->set_time(result.time);
    response->set_steps(result.steps);
    response->set_contacts(result.contacts);
    response->set_awake_bodies(result.awake_bodies);
    response->set_revision(result.revision);
  });
}

}  // namespace graspsim::rpc
