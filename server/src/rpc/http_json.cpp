#include "rpc/http_json.h"

#include <charconv>
#include <cmath>
#include <cstdio>
#include <memory>

#include <google/protobuf/dynamic_message.h>
#include <google/protobuf/struct.pb.h>
#include <google/protobuf/util/json_util.h>

#include "core/error.h"
#include "graspsim/v1/gateway.pb.h"
#include "graspsim/v1/grasp.pb.h"
#include "graspsim/v1/perception.pb.h"
#include "graspsim/v1/recording.pb.h"
#include "graspsim/v1/scene.pb.h"
#include "graspsim/v1/tactile.pb.h"

namespace graspsim::rpc {
namespace {

namespace pb = google::protobuf;

const char* kStatusNames[] = {"OK",
                              "CANCELLED",
                              "UNKNOWN",
                              "INVALID_ARGUMENT",
                              "DEADLINE_EXCEEDED",
                              "NOT_FOUND",
                              "ALREADY_EXISTS",
                              "PERMISSION_DENIED",
                              "RESOURCE_EXHAUSTED",
                              "FAILED_PRECONDITION",
                              "ABORTED",
                              "OUT_OF_RANGE",
                              "UNIMPLEMENTED",
                              "INTERNAL",
                              "UNAVAILABLE",
                              "DATA_LOSS",
                              "UNAUTHENTICATED"};

// The services a client may reach over HTTP: those of the API, not health or reflection. Each is taken from
// its .proto file through one of its messages, which also links that file's descriptors into any binary.
const std::vector<const pb::ServiceDescriptor*>& ApiServices() {
  static const std::vector<const pb::ServiceDescriptor*> services = {
      v1::CreateSceneRequest::descriptor()->file()->service(0),
      v1::CompleteShapeRequest::descriptor()->file()->service(0),
      v1::PlanGraspsRequest::descriptor()->file()->service(0),
      v1::SampleRequest::descriptor()->file()->service(0),
      v1::ListDevicesRequest::descriptor()->file()->service(0),
      v1::StartRecordingRequest::descriptor()->file()->service(0),
  };
  return services;
}

std::unique_ptr<pb::Message> NewMessage(const pb::Descriptor* type) {
  return std::unique_ptr<pb::Message>(pb::MessageFactory::generated_factory()->GetPrototype(type)->New());
}

std::string JsonEscape(std::string_view text) {
  std::string out;
  for (char c : text) {
    switch (c) {
      case '"': out += "\\\""; break;
      case '\\': out += "\\\\"; break;
      case '\n': out += "\\n"; break;
      case '\t': out += "\\t"; break;
      case '\r': out += "\\r"; break;
      default:
        if (static_cast<unsigned char>(c) < 0x20) {
          char escaped[8];
          std::snprintf(escaped, sizeof escaped, "\\u%04x", c);
          out += escaped;
        } else {
          out += c;
        }
    }
  }
  return out;
}

int HexValue(char c) {
  if (c >= '0' && c <= '9') return c - '0';
  if (c >= 'a' && c <= 'f') return c - 'a' + 10;
  if (c >= 'A' && c <= 'F') return c - 'A' + 10;
  return -1;
}

// application/x-www-form-urlencoded decoding of one value ('+' is a space, %XX a byte).
std::string FormDecode(std::string_view text) {
  std::string out;
  out.reserve(text.size());
  for (size_t i = 0; i < text.size(); ++i) {
    if (text[i] == '+') {
      out += ' ';
    } else if (text[i] == '%' && i + 2 < text.size() && HexValue(text[i + 1]) >= 0 && HexValue(text[i + 2]) >= 0) {
      out += static_cast<char>(HexValue(text[i + 1]) * 16 + HexValue(text[i + 2]));
      i += 2;
    } else {
      out += text[i];
    }
  }
  return out;
}

std::string FormPayload(const std::string& body) {
  size_t start = 0;
  while (start <= body.size()) {
    size_t end = body.find('&', start);
    if (end == std::string::npos) end = body.size();
    const std::string_view pair(body.data() + start, end - start);
    if (pair.starts_with("payload=")) return FormDecode(pair.substr(8));
    start = end + 1;
  }
  ThrowInvalidArgument("payload: a form-encoded request needs the field payload=<json>");
}

grpc::ByteBuffer Serialize(const pb::Message& message) {
  const std::string bytes = message.SerializeAsString();
  grpc::Slice slice(bytes);
  return grpc::ByteBuffer(&slice, 1);
}

pb::Message* ParseRequest(const pb::Descriptor* type, const std::string& json, const std::string& where,
                          std::unique_ptr<pb::Message>* holder) {
  *holder = NewMessage(type);
  pb::util::JsonParseOptions options;
  options.ignore_unknown_fields = false;  // a misspelt field is an error, not a silent default
  const auto status = pb::util::JsonStringToMessage(json, holder->get(), options);
  if (!status.ok()) {
    ThrowInvalidArgument(where + ": not a valid " + type->full_name() + " in JSON: " + std::string(status.message()));
  }
  return holder->get();
}

}  // namespace

const pb::MethodDescriptor& FindMethod(const std::string& full_service, const std::string& method) {
  const pb::MethodDescriptor* found = nullptr;
  for (const pb::ServiceDescriptor* service : ApiServices()) {
    if (service->full_name() == full_service) found = service->FindMethodByName(method);
  }
  if (!found) ThrowNotFound("path: no method " + full_service + "/" + method + " (GET /v1 lists them)");
  return *found;
}

std::vector<grpc::ByteBuffer> RequestsFromHttp(const pb::MethodDescriptor& method, std::string_view content_type,
                                               const std::string& body) {
  // curl -d and similar tools label a raw JSON body as a form: take a body that starts like JSON as JSON, and
  // an empty body as the empty message.
  const size_t start = body.find_first_not_of(" \t\r\n");
  const bool looks_like_json = start == std::string::npos || body[start] == '{' || body[start] == '[';
  const bool form = content_type.starts_with("application/x-www-form-urlencoded") && !looks_like_json;
  std::string json = form ? FormPayload(body) : body;
  if (json.find_first_not_of(" \t\r\n") == std::string::npos) json = method.client_streaming() ? "[]" : "{}";
  std::unique_ptr<pb::Message> holder;
  if (!method.client_streaming()) {
    return {Serialize(*ParseRequest(method.input_type(), json, "request", &holder))};
  }
  // A client stream is a JSON array of messages; ListValue parses the array, each element is re-read as JSON.
  pb::ListValue list;
  if (!pb::util::JsonStringToMessage(json, &list).ok()) {
    ThrowInvalidArgument("request: " + method.full_name() + " is a client stream: send a JSON array of " +
                         method.input_type()->full_name() + " messages");
  }
  std::vector<grpc::ByteBuffer> requests;
  for (int i = 0; i < list.values_size(); ++i) {
    std::string element;
    (void)pb::util::MessageToJsonString(list.values(i), &element);
    requests.push_back(
        Serialize(*ParseRequest(method.input_type(), element, "request[" + std::to_string(i) + "]", &holder)));
  }
  return requests;
}

std::string ResponseJson(const pb::MethodDescriptor& method, const grpc::ByteBuffer& response) {
  std::vector<grpc::Slice> slices;
  (void)response.Dump(&slices);
  std::string bytes;
  for (const auto& slice : slices) bytes.append(reinterpret_cast<const char*>(slice.begin()), slice.size());
  auto message = NewMessage(method.output_type());
  if (!message->ParseFromString(bytes)) {
    throw Error(ErrorCode::kInternal, "response of " + method.full_name() + " does not parse");
  }
  pb::util::JsonPrintOptions options;
  options.preserve_proto_field_names = true;
  options.always_print_primitive_fields = true;
  std::string json;
  (void)pb::util::MessageToJsonString(*message, &json, options);
  return json;
}

std::string StatusJson(const grpc::Status& status) {
  const int code = status.error_code();
  const char* name = code >= 0 && code <= 16 ? kStatusNames[code] : "UNKNOWN";
  return "{\"code\":" + std::to_string(code) + ",\"status\":\"" + name + "\",\"message\":\"" +
         JsonEscape(status.error_message()) + "\"}";
}

std::string EnvelopeJson(const grpc::Status& status, const std::string& key, const std::string& json) {
  std::string out = StatusJson(status);
  out.pop_back();
  return out + ",\"" + key + "\":" + json + "}";
}

int HttpStatusFor(grpc::StatusCode code) {
  switch (code) {
    case grpc::StatusCode::OK: return 200;
    case grpc::StatusCode::CANCELLED: return 499;
    case grpc::StatusCode::INVALID_ARGUMENT:
    case grpc::StatusCode::FAILED_PRECONDITION:
    case grpc::StatusCode::OUT_OF_RANGE: return 400;
    case grpc::StatusCode::DEADLINE_EXCEEDED: return 504;
    case grpc::StatusCode::NOT_FOUND: return 404;
    case grpc::StatusCode::ALREADY_EXISTS:
    case grpc::StatusCode::ABORTED: return 409;
    case grpc::StatusCode::PERMISSION_DENIED: return 403;
    case grpc::StatusCode::UNAUTHENTICATED: return 401;
    case grpc::StatusCode::RESOURCE_EXHAUSTED: return 429;
    case grpc::StatusCode::UNIMPLEMENTED: return 501;
    case grpc::StatusCode::UNAVAILABLE: return 503;
    default: return 500;
  }
}

std::string ListMethodsJson() {
  std::string out = "{\"services\":[";
  for (const pb::ServiceDescriptor* service : ApiServices()) {
    out += std::string(service == ApiServices().front() ? "" : ",") + "{\"name\":\"" + service->full_name() +
           "\",\"methods\":[";
    for (int m = 0; m < service->method_count(); ++m) {
      const pb::MethodDescriptor* method = service->method(m);
      out += std::string(m ? "," : "") + "{\"name\":\"" + method->name() + "\",\"input\":\"" +
             method->input_type()->full_name() + "\",\"output\":\"" + method->output_type()->full_name() +
             "\",\"client_streaming\":" + (method->client_streaming() ? "true" : "false") +
             ",\"server_streaming\":" + (method->server_streaming() ? "true" : "false") + "}";
    }
    out += "]}";
  }
  return out + "]}";
}

long ParseCount(const std::string& name, const std::string& text) {
  long value = -1;
  const auto result = std::from_chars(text.data(), text.data() + text.size(), value);
  if (result.ec != std::errc() || result.ptr != text.data() + text.size() || value < 0) {
    ThrowInvalidArgument(name + ": '" + text.substr(0, 40) + "' is not an integer >= 0");
  }
  return value;
}

double ParseSeconds(const std::string& name, const std::string& text) {
  double value = NAN;
  const auto result = std::from_chars(text.data(), text.data() + text.size(), value);
  if (result.ec != std::errc() || result.ptr != text.data() + text.size() || !std::isfinite(value) || value <= 0) {
    ThrowInvalidArgument(name + ": '" + text.substr(0, 40) + "' is not a positive number of seconds");
  }
  return value;
}

std::string JsonString(const std::string& text) {
  std::string out = "\"";
  for (const unsigned char c : text) {
    if (c == '"' || c == '\\') {
      out += '\\';
      out += static_cast<char>(c);
    } else if (c < 0x20) {
      char escaped[8];
      std::snprintf(escaped, sizeof escaped, "\\u%04x", c);
      out += escaped;
    } else {
      out += static_cast<char>(c);
    }
  }
  return out + "\"";
}

std::string JsonNumber(double value, int digits) {
  if (!std::isfinite(value)) return "null";  // never expected (the engine stops on NaN), but keep the JSON valid
  char text[32];
  std::snprintf(text, sizeof text, "%.*g", digits, value);
  return text;
}

}  // namespace graspsim::rpc
