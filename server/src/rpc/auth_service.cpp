#include "rpc/auth_service.h"

#include "core/error.h"
#include "core/log.h"
#include "rpc/auth_interceptor.h"
#include "rpc/call.h"

namespace graspsim::rpc {

void AuthServiceImpl::RequireTokens() const {
  if (!tokens_) {
    throw Error(ErrorCode::kFailedPrecondition, "the server checks no tokens (start it with --token-file)");
  }
}

grpc::ServerUnaryReactor* AuthServiceImpl::WhoAmI(Context* context, const v1::WhoAmIRequest*,
                                                  v1::WhoAmIResponse* response) {
  return RunUnary(context, "AuthService/WhoAmI", pool_, [=] {
    if (const auto who = CallerOf(*context)) {
      response->set_name(who->name);
      response->set_role(auth::RoleName(who->role));
    }
  });
}

grpc::ServerUnaryReactor* AuthServiceImpl::AddToken(Context* context, const v1::AddTokenRequest* request,
                                                    v1::AddTokenResponse*) {
  return RunUnary(context, "AuthService/AddToken", pool_, [=, this] {
    RequireTokens();
    const auto role = auth::ParseRole(request->role());
    if (!role) ThrowInvalidArgument("role: '" + request->role().substr(0, 80) + "' is not one of viewer, scripter, gateway, admin");
    authorizer_->AddToken(*role, request->name(), request->token(), "", /*keep=*/true);
    Log(LogLevel::kInfo, "token added", {{"name", request->name()}, {"role", request->role()}});
  });
}

grpc::ServerUnaryReactor* AuthServiceImpl::RevokeToken(Context* context, const v1::RevokeTokenRequest* request,
                                                       v1::RevokeTokenResponse*) {
  return RunUnary(context, "AuthService/RevokeToken", pool_, [=, this] {
    RequireTokens();
    if (!authorizer_->RevokeToken(request->name())) ThrowNotFound("name: no token named '" + request->name().substr(0, 80) + "'");
    Log(LogLevel::kInfo, "token revoked", {{"name", request->name()}});
  });
}

grpc::ServerUnaryReactor* AuthServiceImpl::GrantDevice(Context* context, const v1::GrantDeviceRequest* request,
                                                       v1::GrantDeviceResponse*) {
  return RunUnary(context, "AuthService/GrantDevice", pool_, [=, this] {
    RequireTokens();
    if (request->device_id().empty()) ThrowInvalidArgument("device_id: empty");
    if (request->name().empty()) ThrowInvalidArgument("name: empty");
    authorizer_->GrantDevice(request->device_id(), request->name(), /*keep=*/true);
    Log(LogLevel::kInfo, "device granted", {{"device_id", request->device_id()}, {"name", request->name()}});
  });
}

grpc::ServerUnaryReactor* AuthServiceImpl::ShareScene(Context* context, const v1::ShareSceneRequest* request,
                                                      v1::ShareSceneResponse*) {
  return RunUnary(context, "AuthService/ShareScene", pool_, [=, this] {
    RequireTokens();
    if (request->name().empty()) ThrowInvalidArgument("name: empty");
    const auto who = CallerOf(*context);
    // The interceptor let only the owner or an admin through; Share checks again against a scene deleted since.
    if (!who || !authorizer_->Share(*who, request->scene_id(), request->name())) {
      ThrowNotFound("scene_id: '" + request->scene_id().substr(0, 80) + "' does not exist");
    }
  });
}

}  // namespace graspsim::rpc
