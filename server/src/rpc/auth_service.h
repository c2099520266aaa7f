// graspsim.v1.AuthService: translation onto auth::Authorizer. The interceptor has already checked the caller's
// role and, for ShareScene, that the caller owns the scene.
#pragma once

#include "auth/auth.h"
#include "core/worker_pool.h"
#include "graspsim/v1/auth.grpc.pb.h"

namespace graspsim::rpc {

class AuthServiceImpl final : public v1::AuthService::CallbackService {
 public:
  // tokens: whether the server checks tokens at all (a --token-file was given).
  AuthServiceImpl(auth::Authorizer* authorizer, bool tokens, WorkerPool* pool)
      : authorizer_(authorizer), tokens_(tokens), pool_(pool) {}

  using Context = grpc::CallbackServerContext;
  using Unary = grpc::ServerUnaryReactor;

  Unary* WhoAmI(Context*, const v1::WhoAmIRequest*, v1::WhoAmIResponse*) override;
  Unary* AddToken(Context*, const v1::AddTokenRequest*, v1::AddTokenResponse*) override;
  Unary* RevokeToken(Context*, const v1::RevokeTokenRequest*, v1::RevokeTokenResponse*) override;
  Unary* GrantDevice(Context*, const v1::GrantDeviceRequest*, v1::GrantDeviceResponse*) override;
  Unary* ShareScene(Context*, const v1::ShareSceneRequest*, v1::ShareSceneResponse*) override;

 private:
  void RequireTokens() const;

  auth::Authorizer* authorizer_;
  bool tokens_;
  WorkerPool* pool_;
};

}  // namespace graspsim::rpc
