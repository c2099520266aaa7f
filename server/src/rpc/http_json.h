// The JSON half of the HTTP gateway: finding a method by name, HTTP bodies → protobuf requests, responses and
// statuses → JSON. Pure functions, no sockets, so the mapping is tested on its own.
#pragma once

#include <string>
#include <string_view>
#include <vector>

#include <google/protobuf/descriptor.h>
#include <grpcpp/grpcpp.h>

namespace graspsim::rpc {

// Error(kNotFound) naming the path when the service or method does not exist.
const google::protobuf::MethodDescriptor& FindMethod(const std::string& full_service, const std::string& method);

// The request messages of one call: one for most methods, the elements of a JSON array for client-streaming
// methods. `content_type` "application/x-www-form-urlencoded" takes the JSON from the form field payload
// (unless the body itself starts like JSON, as curl -d sends it).
// Error(kInvalidArgument) naming the problem (bad JSON, unknown field, wrong type).
std::vector<grpc::ByteBuffer> RequestsFromHttp(const google::protobuf::MethodDescriptor& method,
                                               std::string_view content_type, const std::string& body);

// A response message as JSON: proto field names, every field present, bytes base64, 64-bit integers as strings.
std::string ResponseJson(const google::protobuf::MethodDescriptor& method, const grpc::ByteBuffer& response);

// {"code": 3, "status": "INVALID_ARGUMENT", "message": "..."}
std::string StatusJson(const grpc::Status& status);
// StatusJson plus "<key>": <json> (the response, or the array of a stream's responses).
std::string EnvelopeJson(const grpc::Status& status, const std::string& key, const std::string& json);
// The HTTP status of a gRPC code (google.rpc's mapping).
int HttpStatusFor(grpc::StatusCode code);
// {"services": [{"name": ..., "methods": [{"name", "input", "output", "client_streaming", "server_streaming"}]}]}
std::string ListMethodsJson();

// A JSON string literal (quotes, backslashes and control characters escaped) and a number with `digits`
// significant digits ("null" when not finite), for the hand-built JSON of the viewer routes.
std::string JsonString(const std::string& text);
std::string JsonNumber(double value, int digits = 7);

// Query parameters: Error(kInvalidArgument) naming the parameter.
long ParseCount(const std::string& name, const std::string& text);
double ParseSeconds(const std::string& name, const std::string& text);

}  // namespace graspsim::rpc
