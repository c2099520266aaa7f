#include "rpc/scene_service.h"

#include <cmath>
#include <functional>

#include "core/error.h"
#include "core/validate.h"
#include "rpc/call.h"
#include "rpc/convert.h"
#include "rpc/scene_archive_calls.h"
#include "rpc/scene_edits.h"
#include "rpc/upload_file.h"
#include "rpc/watch_scene.h"

namespace graspsim::rpc {
namespace {

// The body an id names for pose reads: an object, a robot (its base body) or any body.
size_t BodyIndexForRead(const SceneModel& model, const std::string& scene_id, const std::string& id) {
  if (auto robot = model.robot_index.find(id); robot != model.robot_index.end()) {
    return model.body_index.at(model.robots[robot->second].base_body);
  }
  auto body = model.body_index.find(id);
  if (body == model.body_index.end()) ThrowNotFound("body_ids: no body '" + id + "' in scene '" + scene_id + "'");
  return body->second;
}

// A short read of one scene (RunShortRead): in place on gRPC's thread when the registry and the scene are free,
// else on the pool, waiting for them.
template <typename Fill>
grpc::ServerUnaryReactor* ShortSceneRead(grpc::CallbackServerContext* context, const char* method, WorkerPool* pool,
                                         SceneRegistry* registry, const std::string& scene_id, Fill fill) {
  return RunShortRead(
      context, method, pool,
      [=] {
        const std::shared_ptr<Scene> scene = registry->TryGet(scene_id);
        return scene && scene->TryRead(std::cref(fill));  // a reference: no copy of the lambda per call
      },
      [=] { registry->Get(scene_id)->Read(std::cref(fill)); });
}

}  // namespace

grpc::ServerUnaryReactor* SceneServiceImpl::CreateScene(grpc::CallbackServerContext* context, const v1::CreateSceneRequest* request,
                                           v1::Scene* response) {
  return RunUnary(context, "CreateScene", pool_, [=, this] {
    ToProto(registry_->Create(request->name(), request->scene_id())->View(), false, response);
  });
}

grpc::ServerUnaryReactor* SceneServiceImpl::ListScenes(grpc::CallbackServerContext* context, const v1::ListScenesRequest*,
                                          v1::ListScenesResponse* response) {
  return RunUnary(context, "ListScenes", pool_, [=, this] {
    for (const auto& scene : registry_->List()) SummaryToProto(scene->View(), response->add_scenes());
  });
}

grpc::ServerUnaryReactor* SceneServiceImpl::GetScene(grpc::CallbackServerContext* context, const v1::GetSceneRequest* request,
                                        v1::Scene* response) {
  return RunUnary(context, "GetScene", pool_, [=, this] {
    ToProto(registry_->Get(request->scene_id())->View(), request->include_geometry(), response);
  });
}

grpc::ServerUnaryReactor* SceneServiceImpl::DeleteScene(grpc::CallbackServerContext* context, const v1::DeleteSceneRequest* request,
                                           v1::DeleteSceneResponse*) {
  return RunUnary(context, "DeleteScene", pool_, [=, this] {
    registry_->Delete(request->scene_id());
    simulations_->Forget(request->scene_id());
  });
}

grpc::ServerWriteReactor<v1::SceneArchiveChunk>* SceneServiceImpl::ExportScene(Context* context,
                                                                             const v1::ExportSceneRequest* request) {
  return StartStream<v1::SceneArchiveChunk>(context, [&] { return StartExport(context, request, registry_, pool_); });
}

grpc::ServerReadReactor<v1::SceneArchiveChunk>* SceneServiceImpl::ImportScene(Context* context, v1::Scene* response) {
  return StartImport(context, registry_, pool_, response);
}

grpc::ServerReadReactor<v1::UploadFileChunk>* SceneServiceImpl::UploadFile(grpc::CallbackServerContext* context,
                                                                           v1::FileInfo* response) {
  return StartUpload(context, registry_, pool_, response);
}

grpc::ServerUnaryReactor* SceneServiceImpl::ListBuiltinModels(grpc::CallbackServerContext* context, const v1::ListBuiltinModelsRequest*,
                                                 v1::ListBuiltinModelsResponse* response) {
  return RunUnary(context, "ListBuiltinModels", pool_, [response] {
    for (const auto& info : BuiltinModels()) {
      auto* model = response->add_models();
      model->set_name(info.name);
      model->set_kind(info.kind);
      model->set_description(info.description);
    }
  });
}

grpc::ServerUnaryReactor* SceneServiceImpl::AddObject(grpc::CallbackServerContext* context, const v1::AddObjectRequest* request,
                                         v1::Body* response) {
  return RunUnary(context, "AddObject", pool_, [=, this] {
    AddObjectFromRequest(registry_->Get(request->scene_id()).get(), *request, registry_->limits(), response);
  });
}

grpc::ServerUnaryReactor* SceneServiceImpl::AddRobot(grpc::CallbackServerContext* context, const v1::AddRobotRequest* request,
                                        v1::AddRobotResponse* response) {
  return RunUnary(context, "AddRobot", pool_, [=, this] {
    AddRobotFromRequest(registry_->Get(request->scene_id()).get(), *request, registry_->limits(), response);
  });
}

grpc::ServerUnaryReactor* SceneServiceImpl::RemoveBody(grpc::CallbackServerContext* context, const v1::RemoveBodyRequest* request,
                                          v1::RemoveBodyResponse* response) {
  return RunUnary(context, "RemoveBody", pool_, [=, this] {
    for (const auto& id : RemoveBodyFromRequest(registry_->Get(request->scene_id()).get(), *request)) {
      response->add_removed_body_ids(id);
    }
  });
}

grpc::ServerUnaryReactor* SceneServiceImpl::SetBodyPoses(grpc::CallbackServerContext* context, const v1::SetBodyPosesRequest* request,
                                            v1::SetBodyPosesResponse* response) {
  return RunUnary(context, "SetBodyPoses", pool_, [=, this] {
    auto scene = registry_->Get(request->scene_id());
    std::vector<std::pair<std::string, Pose>> poses;
    std::vector<std::pair<std::string, BodyVelocity>> velocities;
    for (int i = 0; i < request->poses_size(); ++i) {
      const auto& entry = request->poses(i);
      if (entry.has_pose() || !entry.has_velocity()) {
        poses.emplace_back(entry.body_id(), PoseFromProto("poses[" + std::to_string(i) + "].pose", entry.pose()));
      }
      if (entry.has_velocity()) {
        velocities.emplace_back(entry.body_id(), BodyVelocity{FromProto(entry.velocity().linear()),
                                                              FromProto(entry.velocity().angular())});
      }
    }
    response->set_revision(scene->SetBodyPoses(poses, velocities));
  });
}

grpc::ServerUnaryReactor* SceneServiceImpl::GetBodyPoses(grpc::CallbackServerContext* context, const v1::GetBodyPosesRequest* request,
                                            v1::GetBodyPosesResponse* response) {
  const std::string& scene_id = request->scene_id();
  return ShortSceneRead(context, "GetBodyPoses", pool_, registry_, scene_id,
                        [request, response, &scene_id](const SceneModel& model, const SceneState& state, uint64_t revision) {
    auto add = [&](const std::string& id, size_t index) {
      auto* entry = response->add_poses();
      entry->set_body_id(id);
      ToProto(state.body_poses[index], entry->mutable_pose());
      if (model.bodies[index].motion == BodyMotion::kFree && index < state.body_velocities.size()) {
        ToProto(state.body_velocities[index].linear, entry->mutable_velocity()->mutable_linear());
        ToProto(state.body_velocities[index].angular, entry->mutable_velocity()->mutable_angular());
      }
    };
    if (request->body_ids().empty()) {
      for (size_t i = 0; i < model.bodies.size(); ++i) add(model.bodies[i].id, i);
    }
    for (const auto& id : request->body_ids()) add(id, BodyIndexForRead(model, scene_id, id));
    response->set_revision(revision);
    response->set_time(state.time);
  });
}

grpc::ServerUnaryReactor* SceneServiceImpl::SetJointPositions(grpc::CallbackServerContext* context,
                                                 const v1::SetJointPositionsRequest* request,
                                                 v1::SetJointPositionsResponse* response) {
  return RunUnary(context, "SetJointPositions", pool_, [=, this] {
    auto scene = registry_->Get(request->scene_id());
    std::vector<std::pair<std::string, double>> positions, velocities;
    for (const auto& entry : request->positions()) {
      positions.emplace_back(entry.joint_id(), entry.position());
      if (entry.has_velocity()) velocities.emplace_back(entry.joint_id(), entry.velocity());
    }
    response->set_revision(scene->SetJointPositions(positions, velocities));
  });
}

grpc::ServerUnaryReactor* SceneServiceImpl::GetJointPositions(grpc::CallbackServerContext* context,
                                                 const v1::GetJointPositionsRequest* request,
                                                 v1::GetJointPositionsResponse* response) {
  const std::string& scene_id = request->scene_id();
  return ShortSceneRead(context, "GetJointPositions", pool_, registry_, scene_id,
                        [request, response, &scene_id](const SceneModel& model, const SceneState& state, uint64_t revision) {
    auto add = [&](const std::string& id, size_t index) {
      auto* entry = response->add_positions();
      entry->set_joint_id(id);
      entry->set_position(state.joint_positions[index]);
      entry->set_velocity(index < state.joint_velocities.size() ? state.joint_velocities[index] : 0.0);
    };
    if (request->joint_ids().empty()) {
      for (size_t j = 0; j < model.joints.size(); ++j) add(model.joints[j].id, j);
    }
    for (const auto& id : request->joint_ids()) {
      auto it = model.joint_index.find(id);
      if (it == model.joint_index.end()) ThrowNotFound("joint_ids: no joint '" + id + "' in scene '" + scene_id + "'");
      add(id, it->second);
    }
    response->set_revision(revision);
  });
}

grpc::ServerWriteReactor<v1::SceneSnapshot>* SceneServiceImpl::WatchScene(grpc::CallbackServerContext* context,
                                                                          const v1::WatchSceneRequest* request) {
  std::shared_ptr<Scene> scene;
  double rate = watch_max_rate_hz_;
  return StartStream<v1::SceneSnapshot>(
      "WatchScene", context,
      [&] {
        const double requested = request->max_rate_hz();
        if (!std::isfinite(requested) || requested < 0) {
          ThrowInvalidArgument("max_rate_hz: " + std::to_string(requested) + " must be a finite number >= 0");
        }
        if (requested > 0) rate = std::min(requested, watch_max_rate_hz_);
        scene = registry_->Get(request->scene_id());
      },
      [&] { return StartWatch(std::move(scene), std::chrono::nanoseconds(static_cast<int64_t>(1e9 / rate))); });
}

}  // namespace graspsim::rpc
