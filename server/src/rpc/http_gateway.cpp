#include "rpc/http_gateway.h"

#include <cmath>
#include <thread>

#include <google/protobuf/descriptor.h>
#include <google/protobuf/dynamic_message.h>
#include <google/protobuf/struct.pb.h>
#include <google/protobuf/util/json_util.h>
#include <grpcpp/generic/generic_stub.h>
#include <httplib.h>

#include "core/error.h"
#include "core/log.h"
#include "rpc/call.h"
#include "rpc/http_json.h"
#include "rpc/http_viewer.h"

namespace graspsim::rpc {
namespace {

namespace pb = google::protobuf;

constexpr char kPackage[] = "graspsim.v1.";

// One gRPC call through the generic stub, driven step by step on its own completion queue: the HTTP thread
// that owns it blocks on each step, which is what an HTTP request-per-thread server expects.
class GenericCall {
 public:
  GenericCall(grpc::GenericStub* stub, const std::string& path, std::unique_ptr<grpc::ClientContext> context)
      : context_(std::move(context)), call_(stub->PrepareCall(context_.get(), path, &queue_)) {
    call_->StartCall(this);
    started_ = Wait();
  }
  ~GenericCall() {
    queue_.Shutdown();
    void* tag;
    bool ok;
    while (queue_.Next(&tag, &ok)) {
    }
  }

  // Sends every request, then half-closes. Returns false if the call already ended (Finish tells why).
  bool SendAll(const std::vector<grpc::ByteBuffer>& requests) {
    if (!started_) return false;
    for (const auto& request : requests) {
      call_->Write(request, this);
      if (!Wait()) return false;
    }
    call_->WritesDone(this);
    return Wait();
  }
  bool Read(grpc::ByteBuffer* response) {
    call_->Read(response, this);
    return Wait();
  }
  void Cancel() { context_->TryCancel(); }
  grpc::Status Finish() {
    grpc::Status status;
    call_->Finish(&status, this);
    Wait();
    return status;
  }

 private:
  bool Wait() {
    void* tag;
    bool ok = false;
    queue_.Next(&tag, &ok);
    return ok;
  }

  grpc::CompletionQueue queue_;
  std::unique_ptr<grpc::ClientContext> context_;
  std::unique_ptr<grpc::GenericClientAsyncReaderWriter> call_;
  bool started_ = false;
};

struct CallOptions {
  bool envelope = false;
  long max_messages = -1;    // < 0: no limit
  bool max_seconds = false;  // the deadline ends a stream normally, like max_messages
};

bool Wants(const CallOptions& options, long sent) { return options.max_messages < 0 || sent < options.max_messages; }

// Ends a stream: cancelled by us once max_messages were sent or max_seconds passed (both reported as OK),
// otherwise its own status.
grpc::Status FinishAfter(GenericCall& call, long sent, const CallOptions& options) {
  if (options.max_messages >= 0 && sent >= options.max_messages) {
    call.Cancel();
    call.Finish();
    return grpc::Status(grpc::StatusCode::OK, "max_messages reached");
  }
  const grpc::Status status = call.Finish();
  if (options.max_seconds && status.error_code() == grpc::StatusCode::DEADLINE_EXCEEDED) {
    return grpc::Status(grpc::StatusCode::OK, "max_seconds reached");
  }
  return status;
}

void ReplyStatus(const grpc::Status& status, const CallOptions& options, httplib::Response& res) {
  res.status = options.envelope ? 200 : HttpStatusFor(status.error_code());
  res.set_content(StatusJson(status), "application/json");
}

std::string SseEvent(const char* event, const std::string& json) {
  return std::string("event: ") + event + "\ndata: " + json + "\n\n";
}

}  // namespace

struct HttpGateway::Impl {
  Impl(std::shared_ptr<grpc::Channel> channel, const HttpGatewayOptions& options)
      : stub(channel), server_ptr(MakeServer(options)), server(*server_ptr) {
    server.new_task_queue = [threads = options.threads] { return new httplib::ThreadPool(threads); };
    server.set_payload_max_length(options.max_body_bytes);
    server.Get("/v1", [](const httplib::Request&, httplib::Response& res) {
      res.set_content(ListMethodsJson(), "application/json");
    });
    // The body is read here rather than by httplib, which refuses form bodies above 8 KiB (its
    // CPPHTTPLIB_FORM_URL_ENCODED_PAYLOAD_MAX_LENGTH, compiled into Debian's library) — and Octave sends every
    // request as a form. set_payload_max_length still bounds every body.
    server.Post(R"(/v1/([A-Za-z0-9_.]+)/([A-Za-z0-9_]+))",
                [this](const httplib::Request& req, httplib::Response& res, const httplib::ContentReader& read) {
                  std::string body;
                  read([&body](const char* data, size_t length) {
                    body.append(data, length);
                    return true;
                  });
                  HandleCall(req, body, res);
                });
    AddViewerRoutes(&server, std::move(channel), options.viewer_dir, options.overlays);
  }

  void HandleCall(const httplib::Request& req, const std::string& body, httplib::Response& res);
  void Stream(std::shared_ptr<GenericCall> call, const pb::MethodDescriptor& method, const CallOptions& options,
              httplib::Response& res);

  // TLS when a certificate is given (the same files as the gRPC port), else plain HTTP.
  static std::unique_ptr<httplib::Server> MakeServer(const HttpGatewayOptions& options) {
    if (options.tls_cert.empty()) return std::make_unique<httplib::Server>();
    auto server = std::make_unique<httplib::SSLServer>(options.tls_cert.c_str(), options.tls_key.c_str());
    if (!server->is_valid()) {
      throw Error(ErrorCode::kInvalidArgument, "--tls-cert/--tls-key: OpenSSL cannot use '" + options.tls_cert +
                                                   "' with '" + options.tls_key + "' for the HTTP port");
    }
    return server;
  }

  grpc::GenericStub stub;
  std::unique_ptr<httplib::Server> server_ptr;
  httplib::Server& server;
  std::thread thread;
  int port = 0;
};

void HttpGateway::Impl::HandleCall(const httplib::Request& req, const std::string& body, httplib::Response& res) {
  CallOptions options;
  options.envelope = req.get_param_value("envelope") == "1" || req.get_param_value("envelope") == "true";
  try {
    std::string service = req.matches[1];
    if (!service.starts_with(kPackage)) service = kPackage + service;
    const pb::MethodDescriptor& method = FindMethod(service, req.matches[2]);
    if (method.client_streaming() && method.server_streaming()) {
      throw Error(ErrorCode::kUnimplemented, service + "/" + method.name() +
                                                 " is a bidirectional stream, which is not available over HTTP");
    }
    if (req.has_param("max_messages")) options.max_messages = ParseCount("max_messages", req.get_param_value("max_messages"));
    auto context = std::make_unique<grpc::ClientContext>();
    // timeout_s is a deadline (DEADLINE_EXCEEDED when it passes); max_seconds ends a stream normally.
    const char* deadline_param = nullptr;
    if (req.has_param("timeout_s")) deadline_param = "timeout_s";
    if (method.server_streaming() && req.has_param("max_seconds")) {
      deadline_param = "max_seconds";
      options.max_seconds = true;
    }
    if (deadline_param) {
      const double timeout = ParseSeconds(deadline_param, req.get_param_value(deadline_param));
      context->set_deadline(std::chrono::system_clock::now() +
                            std::chrono::duration_cast<std::chrono::system_clock::duration>(
                                std::chrono::duration<double>(timeout)));
    }
    // Credentials travel as they would over gRPC, for the one interceptor that checks them.
    if (const std::string authorization = AuthorizationOf(req); !authorization.empty()) {
      context->AddMetadata("authorization", authorization);
    }
    const std::vector<grpc::ByteBuffer> requests = RequestsFromHttp(method, req.get_header_value("Content-Type"), body);

    auto call = std::make_shared<GenericCall>(&stub, "/" + service + "/" + method.name(), std::move(context));
    call->SendAll(requests);
    if (method.server_streaming()) {
      Stream(std::move(call), method, options, res);
      return;
    }
    grpc::ByteBuffer response;
    const bool got = call->Read(&response);
    const grpc::Status status = call->Finish();
    if (!status.ok() || !got) {
      ReplyStatus(status.ok() ? grpc::Status(grpc::StatusCode::INTERNAL, "no response") : status, options, res);
      return;
    }
    const std::string json = ResponseJson(method, response);
    res.set_content(options.envelope ? EnvelopeJson(status, "response", json) : json, "application/json");
  } catch (const Error& error) {
    ReplyStatus(ToStatus(error), options, res);
  }
}

void HttpGateway::Impl::Stream(std::shared_ptr<GenericCall> call, const pb::MethodDescriptor& method,
                               const CallOptions& options, httplib::Response& res) {
  // Read the first message before choosing the response: a call that fails at once gets a plain error with
  // its HTTP status, like a unary call.
  auto first = std::make_shared<grpc::ByteBuffer>();
  if (options.max_messages == 0 || !call->Read(first.get())) {
    const grpc::Status status = FinishAfter(*call, 0, options);
    if (options.envelope) return res.set_content(EnvelopeJson(status, "responses", "[]"), "application/json");
    if (!status.ok()) return ReplyStatus(status, options, res);
    return res.set_content(SseEvent("status", StatusJson(status)), "text/event-stream");
  }
  if (options.envelope) {
    std::string responses = "[" + ResponseJson(method, *first);
    long sent = 1;
    grpc::ByteBuffer next;
    while (Wants(options, sent) && call->Read(&next)) {
      responses += "," + ResponseJson(method, next);
      ++sent;
    }
    const grpc::Status status = FinishAfter(*call, sent, options);
    res.set_content(EnvelopeJson(status, "responses", responses + "]"), "application/json");
    return;
  }
  res.set_chunked_content_provider(
      "text/event-stream", [call, first, method = &method, options](size_t, httplib::DataSink& sink) {
        auto send = [&sink, method](const grpc::ByteBuffer& message) {
          const std::string event = SseEvent("message", ResponseJson(*method, message));
          return sink.write(event.data(), event.size());
        };
        bool open = send(*first);
        long sent = 1;
        grpc::ByteBuffer next;
        while (open && Wants(options, sent) && call->Read(&next)) {
          open = send(next);
          ++sent;
        }
        if (!open) {  // the browser went away: end the server-side stream too
          call->Cancel();
          call->Finish();
          return false;
        }
        const std::string end = SseEvent("status", StatusJson(FinishAfter(*call, sent, options)));
        sink.write(end.data(), end.size());
        sink.done();
        return true;
      });
}

HttpGateway::HttpGateway(std::shared_ptr<grpc::Channel> channel, const HttpGatewayOptions& options)
    : impl_(std::make_unique<Impl>(std::move(channel), options)) {
  const size_t colon = options.listen.rfind(':');
  int port = -1;
  if (colon != std::string::npos) {
    try {
      port = std::stoi(options.listen.substr(colon + 1));
    } catch (const std::exception&) {
    }
  }
  if (port < 0 || port > 65535) {
    throw Error(ErrorCode::kFailedPrecondition, "--http-listen: '" + options.listen + "' is not host:port");
  }
  const std::string host = options.listen.substr(0, colon);
  impl_->port = port == 0 ? impl_->server.bind_to_any_port(host) : (impl_->server.bind_to_port(host, port) ? port : -1);
  if (impl_->port <= 0) {
    throw Error(ErrorCode::kFailedPrecondition, "--http-listen: cannot listen on '" + options.listen + "'");
  }
  impl_->thread = std::thread([this] { impl_->server.listen_after_bind(); });
  Log(LogLevel::kInfo, "http listening", {{"address", options.listen}, {"port", std::to_string(impl_->port)}});
}

HttpGateway::~HttpGateway() { Stop(); }

int HttpGateway::port() const { return impl_->port; }

void HttpGateway::Stop() {
  if (!impl_->thread.joinable()) return;
  impl_->server.stop();
  impl_->thread.join();
}

}  // namespace graspsim::rpc
