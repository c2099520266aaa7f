#include "rpc/auth_interceptor.h"

#include <atomic>
#include <fstream>
#include <mutex>
#include <sstream>
#include <unordered_map>
#include <vector>

#include <google/protobuf/message.h>

#include "core/error.h"
#include "core/log.h"
#include "graspsim/v1/scene.pb.h"
#include "graspsim/v1/recording.pb.h"

namespace graspsim::rpc {

using auth::Authorizer, auth::BearerToken, auth::Decision, auth::Identity, auth::MethodRule, auth::Role,
    auth::RoleTable, auth::Verdict;

namespace {

using grpc::experimental::InterceptionHookPoints;

// Calls whose state a handler may ask for: refused calls and AuthService calls. Others are not stored, so an
// allowed call costs no lock here. Entries live exactly as long as the call's interceptor.
struct CallState {
  std::optional<grpc::Status> refused;
  std::optional<Identity> who;
};
std::mutex calls_mutex;
std::unordered_map<const grpc::ServerContextBase*, CallState> calls;
// calls.size(), readable without the lock: while no call is refused (the usual case) RefusedCall takes no lock.
std::atomic<size_t> calls_stored{0};

std::string FieldText(const google::protobuf::Message& message, const std::string& name) {
  const auto* field = message.GetDescriptor()->FindFieldByName(name);
  if (field == nullptr || field->type() != google::protobuf::FieldDescriptor::TYPE_STRING || field->is_repeated()) {
    return "";
  }
  return message.GetReflection()->GetString(message, field);
}

// Every scene a request names: string fields called scene_id or *_scene_id, at the top (GetScene's scene_id,
// CompleteShape's add_to_scene_id) and in message fields below it, set or repeated (UploadFile's header,
// PlanGrasps' object, each of PlanArmPaths' problems), two levels deep.
void CollectSceneIds(const google::protobuf::Message& message, int depth, std::vector<std::string>* ids) {
  const auto* descriptor = message.GetDescriptor();
  const auto* reflection = message.GetReflection();
  for (int i = 0; i < descriptor->field_count(); ++i) {
    const auto* field = descriptor->field(i);
    if (field->type() == google::protobuf::FieldDescriptor::TYPE_MESSAGE && depth < 2) {
      if (field->is_repeated()) {
        for (int k = 0; k < reflection->FieldSize(message, field); ++k) {
          CollectSceneIds(reflection->GetRepeatedMessage(message, field, k), depth + 1, ids);
        }
      } else if (reflection->HasField(message, field)) {
        CollectSceneIds(reflection->GetMessage(message, field), depth + 1, ids);
      }
    } else if (!field->is_repeated() && field->type() == google::protobuf::FieldDescriptor::TYPE_STRING &&
               (field->name() == "scene_id" || field->name().ends_with("_scene_id"))) {
      std::string id = reflection->GetString(message, field);
      if (!id.empty()) ids->push_back(std::move(id));
    }
  }
}

bool IsAuthServiceMethod(std::string_view method) { return method.starts_with("/graspsim.v1.AuthService/"); }

// Commands that move or stop hardware: every one is logged with its sender.
bool IsHardwareCommand(std::string_view method, const MethodRule* rule) {
  return (rule != nullptr && rule->device_grant) || method == "/graspsim.v1.GatewayService/EmergencyStop";
}

grpc::Status StatusOf(const Decision& decision) {
  return grpc::Status(decision.verdict == Verdict::kUnauthenticated ? grpc::StatusCode::UNAUTHENTICATED
                                                                     : grpc::StatusCode::PERMISSION_DENIED,
                      decision.message);
}

class AuthInterceptor : public grpc::experimental::Interceptor {
 public:
  AuthInterceptor(grpc::experimental::ServerRpcInfo* info, Authorizer* authorizer, const InterceptorOptions& options)
      : context_(info->server_context()), method_(info->method()), authorizer_(authorizer), options_(options) {
    const auto& table = RoleTable();
    const auto rule = table.find(method_);
    if (rule != table.end()) rule_ = &rule->second;
    keep_state_ = IsAuthServiceMethod(method_);
    graspsim_method_ = method_.starts_with("/graspsim.v1.");
    hardware_command_ = IsHardwareCommand(method_, rule_);
  }
  ~AuthInterceptor() override {
    if (!stored_) return;
    std::lock_guard lock(calls_mutex);
    calls.erase(context_);
    calls_stored.store(calls.size(), std::memory_order_release);
  }

  void Intercept(grpc::experimental::InterceptorBatchMethods* methods) override {
    if (methods->QueryInterceptionHookPoint(InterceptionHookPoints::POST_RECV_INITIAL_METADATA)) {
      OnMetadata(*methods->GetRecvInitialMetadata());
    }
    // Only graspsim's own services are sure to carry protobuf messages (the health service reads raw bytes).
    if (graspsim_method_ && methods->QueryInterceptionHookPoint(InterceptionHookPoints::POST_RECV_MESSAGE)) {
      if (const void* message = methods->GetRecvMessage()) OnRequest(*static_cast<const google::protobuf::Message*>(message));
    }
    if (graspsim_method_ && methods->QueryInterceptionHookPoint(InterceptionHookPoints::PRE_SEND_MESSAGE)) {
      OnResponse(methods);
    }
    // gRPC's own services (reflection) never ask for the verdict, and an interceptor cannot end a call: a refused
    // caller's requests to them arrive empty (reflection answers an empty request with an error, not a listing)
    // and the call ends with the refusal whatever the service sent. The status is the safety net for graspsim's
    // handlers too, which answer the refusal themselves (rpc/call.h).
    if (refused_ && method_.starts_with("/grpc.reflection.") &&
        methods->QueryInterceptionHookPoint(InterceptionHookPoints::POST_RECV_MESSAGE)) {
      if (void* message = methods->GetRecvMessage()) static_cast<google::protobuf::Message*>(message)->Clear();
    }
    if (methods->QueryInterceptionHookPoint(InterceptionHookPoints::PRE_SEND_STATUS)) {
      if (refused_) {
        methods->ModifySendStatus(refusal_);
      } else if (method_ == "/graspsim.v1.SceneService/DeleteScene" && methods->GetSendStatus().ok() &&
                 options_.tokens) {
        authorizer_->ForgetScene(scene_id_);
      }
    }
    methods->Proceed();
  }

 private:
  void OnMetadata(const std::multimap<grpc::string_ref, grpc::string_ref>& metadata) {
    std::string cert_name;
    if (!options_.tokens && !options_.gateway_needs_cert) return Store();  // nothing to check
    if (const auto auth_context = context_->auth_context(); auth_context && auth_context->IsPeerAuthenticated()) {
      const auto names = auth_context->FindPropertyValues("x509_common_name");
      if (!names.empty()) cert_name.assign(names.front().data(), names.front().size());
    }
    if (options_.gateway_needs_cert && method_ == "/graspsim.v1.GatewayService/Connect" && cert_name.empty()) {
      return Refuse(grpc::Status(grpc::StatusCode::UNAUTHENTICATED,
                                 "GatewayService/Connect needs a client certificate signed by --tls-client-ca"));
    }
    if (!options_.tokens) return Store();
    std::string_view token;
    if (const auto it = metadata.find("authorization"); it != metadata.end()) {
      token = BearerToken(std::string_view(it->second.data(), it->second.size()));
    }
    const Decision decision = authorizer_->Authorize(method_, token, cert_name);
    if (decision.verdict != Verdict::kAllow) return Refuse(StatusOf(decision));
    who_ = decision.who;
    Store();
  }

  void OnRequest(const google::protobuf::Message& request) {
    // Reflection is not free: only commands to hardware name a device.
    const std::string device_id = hardware_command_ ? FieldText(request, "device_id") : std::string();
    if (!refused_ && options_.tokens && rule_ != nullptr && !request_checked_) {
      request_checked_ = true;  // the first message names the scene (UploadFile's header); later chunks carry data
      scene_id_ = FieldText(request, "scene_id");  // DeleteScene's, forgotten when the delete succeeds
      std::vector<std::string> scene_ids;
      CollectSceneIds(request, 0, &scene_ids);
      if (scene_ids.empty()) scene_ids.emplace_back();  // still checks the device grant
      for (const auto& id : scene_ids) {
        const Decision decision = authorizer_->AuthorizeRequest(who_, *rule_, id, device_id);
        if (decision.verdict != Verdict::kAllow) {
          Refuse(StatusOf(decision));
          break;
        }
      }
    }
    if (hardware_command_) {
      // Every command to hardware is logged with its sender (the token's name, never the secret).
      Log(LogLevel::kInfo, "gateway command",
          {{"method", method_}, {"device_id", device_id}, {"by", options_.tokens ? who_.name : "anyone (tokens off)"},
           {"refused", refused_ ? "yes" : "no"}});
    }
  }

  void OnResponse(grpc::experimental::InterceptorBatchMethods* methods) {
    if (refused_ || !options_.tokens) return;
    const void* message = methods->GetSendMessage();
    if (message == nullptr) return;
    if (method_ == "/graspsim.v1.SceneService/CreateScene" || method_ == "/graspsim.v1.SceneService/ImportScene") {
      authorizer_->SetOwner(static_cast<const v1::Scene*>(message)->summary().id(), who_.name);
    } else if (method_ == "/graspsim.v1.RecordingService/ReplayRecording") {
      authorizer_->SetOwner(static_cast<const v1::ReplayRecordingResponse*>(message)->scene_id(), who_.name);
    } else if (method_ == "/graspsim.v1.SceneService/ListScenes" && who_.role != Role::kAdmin) {
      for (const auto& scene : static_cast<const v1::ListScenesResponse*>(message)->scenes()) {
        if (authorizer_->CanRead(who_, scene.id())) *visible_.add_scenes() = scene;
      }
      methods->ModifySendMessage(&visible_);
    }
  }

  void Refuse(const grpc::Status& status) {
    refused_ = true;
    refusal_ = status;
    Log(LogLevel::kInfo, "refused", {{"method", method_}, {"code", std::to_string(status.error_code())},
                                     {"message", status.error_message()}, {"peer", context_->peer()}});
    std::lock_guard lock(calls_mutex);
    calls[context_].refused = status;
    calls_stored.store(calls.size(), std::memory_order_release);
    stored_ = true;
  }

  void Store() {
    if (!keep_state_) return;
    std::lock_guard lock(calls_mutex);
    if (options_.tokens) calls[context_].who = who_;
    else calls[context_];
    calls_stored.store(calls.size(), std::memory_order_release);
    stored_ = true;
  }

  grpc::ServerContextBase* context_;
  std::string method_;
  Authorizer* authorizer_;
  InterceptorOptions options_;
  const MethodRule* rule_ = nullptr;
  grpc::Status refusal_;  // the status a refused call ends with
  bool graspsim_method_ = false, keep_state_ = false, hardware_command_ = false, stored_ = false, refused_ = false,
       request_checked_ = false;
  Identity who_;
  std::string scene_id_;
  v1::ListScenesResponse visible_;
};

class Factory : public grpc::experimental::ServerInterceptorFactoryInterface {
 public:
  bool NeedsInterceptorWithoutTokens(std::string_view method) const {
    if (IsAuthServiceMethod(method)) return true;  // CallerOf reads the stored call
    if (!method.starts_with("/graspsim.v1.GatewayService/")) return false;  // the hardware is all there
    if (options_.gateway_needs_cert && method == "/graspsim.v1.GatewayService/Connect") return true;
    const auto& table = RoleTable();
    const auto rule = table.find(method);
    return IsHardwareCommand(method, rule == table.end() ? nullptr : &rule->second);
  }

  Factory(Authorizer* authorizer, const InterceptorOptions& options) : authorizer_(authorizer), options_(options) {}
  // No interceptor at all (gRPC allows nullptr) for a call that has nothing to be checked, stored or logged:
  // with tokens off that is every call but AuthService's, gateway commands and a gateway's Connect under mTLS.
  // Per call the interceptor's hooks cost the cheap scene reads about a sixth of their server CPU
  // (tests/bench/run rpc, docs/benchmarks.md).
  grpc::experimental::Interceptor* CreateServerInterceptor(grpc::experimental::ServerRpcInfo* info) override {
    if (!options_.tokens && !NeedsInterceptorWithoutTokens(info->method() ? info->method() : "")) return nullptr;
    return new AuthInterceptor(info, authorizer_, options_);
  }

 private:
  Authorizer* authorizer_;
  InterceptorOptions options_;
};

}  // namespace

std::string ReadPemFile(const std::string& flag, const std::string& path) {
  std::ifstream file(path, std::ios::binary);
  if (!file) ThrowInvalidArgument("--" + flag + ": cannot read '" + path + "'");
  std::ostringstream text;
  text << file.rdbuf();
  if (text.str().find("-----BEGIN ") == std::string::npos) {
    ThrowInvalidArgument("--" + flag + ": '" + path + "' is not a PEM file (no -----BEGIN line)");
  }
  return text.str();
}

std::shared_ptr<grpc::ServerCredentials> ServerCredentials(const TlsFiles& tls) {
  if (tls.cert.empty()) return grpc::InsecureServerCredentials();
  // One port for everyone: client certificates are requested and verified when presented, and the
  // interceptor requires one for GatewayService/Connect (scripts and viewers come with tokens only).
  grpc::SslServerCredentialsOptions options(tls.client_ca.empty()
                                                ? GRPC_SSL_DONT_REQUEST_CLIENT_CERTIFICATE
                                                : GRPC_SSL_REQUEST_CLIENT_CERTIFICATE_AND_VERIFY);
  if (!tls.client_ca.empty()) options.pem_root_certs = ReadPemFile("tls-client-ca", tls.client_ca);
  options.pem_key_cert_pairs.push_back({ReadPemFile("tls-key", tls.key), ReadPemFile("tls-cert", tls.cert)});
  return grpc::SslServerCredentials(options);
}

std::unique_ptr<grpc::experimental::ServerInterceptorFactoryInterface> MakeInterceptorFactory(
    Authorizer* authorizer, const InterceptorOptions& options) {
  return std::make_unique<Factory>(authorizer, options);
}

std::optional<grpc::Status> RefusedCall(const grpc::ServerContextBase& context) {
  // The interceptor stores before the handler runs (same call, happens-before through gRPC's batch), so a
  // zero here means this call has no entry.
  if (calls_stored.load(std::memory_order_acquire) == 0) return std::nullopt;
  std::lock_guard lock(calls_mutex);
  const auto it = calls.find(&context);
  if (it == calls.end()) return std::nullopt;
  return it->second.refused;
}

std::optional<Identity> CallerOf(const grpc::ServerContextBase& context) {
  std::lock_guard lock(calls_mutex);
  const auto it = calls.find(&context);
  if (it == calls.end()) return std::nullopt;
  return it->second.who;
}

}  // namespace graspsim::rpc
