// The HTTP gateway's JSON mapping, without sockets: method lookup, bodies to requests, responses and statuses.
#include "rpc/http_json.h"

#include <gtest/gtest.h>

#include "graspsim/v1/scene.pb.h"
#include "test_util.h"

namespace graspsim::rpc {
namespace {

using test_util::ExpectError;

template <typename Message>
Message Decode(const grpc::ByteBuffer& buffer) {
  std::vector<grpc::Slice> slices;
  EXPECT_TRUE(buffer.Dump(&slices).ok());
  std::string bytes;
  for (const auto& slice : slices) bytes.append(reinterpret_cast<const char*>(slice.begin()), slice.size());
  Message message;
  EXPECT_TRUE(message.ParseFromString(bytes));
  return message;
}

grpc::ByteBuffer Encode(const google::protobuf::Message& message) {
  grpc::Slice slice(message.SerializeAsString());
  return grpc::ByteBuffer(&slice, 1);
}

TEST(HttpJson, FindsApiMethodsOnly) {
  EXPECT_EQ(FindMethod("graspsim.v1.SceneService", "CreateScene").input_type()->full_name(),
            "graspsim.v1.CreateSceneRequest");
  ExpectError([] { FindMethod("graspsim.v1.SceneService", "Nope"); }, ErrorCode::kNotFound,
              {"graspsim.v1.SceneService/Nope"});
  // Health and reflection are gRPC plumbing, not part of the API reachable over HTTP.
  ExpectError([] { FindMethod("grpc.health.v1.Health", "Check"); }, ErrorCode::kNotFound, {"grpc.health.v1"});
}

TEST(HttpJson, JsonBodyBecomesTheRequest) {
  const auto& method = FindMethod("graspsim.v1.SceneService", "SetBodyPoses");
  const auto requests = RequestsFromHttp(
      method, "application/json",
      R"({"scene_id": "scene-1", "poses": [{"bodyId": "cube", "pose": {"position": {"z": 0.775}}}]})");
  ASSERT_EQ(requests.size(), 1u);
  const auto request = Decode<v1::SetBodyPosesRequest>(requests[0]);
  EXPECT_EQ(request.scene_id(), "scene-1");
  EXPECT_EQ(request.poses(0).body_id(), "cube");  // lowerCamelCase accepted too
  EXPECT_DOUBLE_EQ(request.poses(0).pose().position().z(), 0.775);
}

TEST(HttpJson, FormPayloadIsDecoded) {
  const auto& method = FindMethod("graspsim.v1.SceneService", "CreateScene");
  // Octave's webwrite(url, 'payload', '{"name":"a b+c"}') sends exactly this.
  const auto requests = RequestsFromHttp(method, "application/x-www-form-urlencoded",
                                         "other=1&payload=%7B%22name%22%3A%22a+b%2Bc%22%7D");
  EXPECT_EQ(Decode<v1::CreateSceneRequest>(requests[0]).name(), "a b+c");
  ExpectError([&] { RequestsFromHttp(method, "application/x-www-form-urlencoded", "name=x"); },
              ErrorCode::kInvalidArgument, {"payload"});
  // curl -d labels raw JSON as a form.
  EXPECT_EQ(Decode<v1::CreateSceneRequest>(
                RequestsFromHttp(method, "application/x-www-form-urlencoded", R"({"name":"curl"})")[0])
                .name(),
            "curl");
}

TEST(HttpJson, EmptyBodyIsTheEmptyMessage) {
  const auto& method = FindMethod("graspsim.v1.SceneService", "ListScenes");
  EXPECT_EQ(RequestsFromHttp(method, "application/json", "").size(), 1u);
  EXPECT_EQ(RequestsFromHttp(method, "application/x-www-form-urlencoded", "").size(), 1u);  // curl -d ''

  EXPECT_TRUE(RequestsFromHttp(FindMethod("graspsim.v1.SceneService", "UploadFile"), "", " ").empty());
}

TEST(HttpJson, ClientStreamTakesAnArray) {
  const auto& method = FindMethod("graspsim.v1.SceneService", "UploadFile");
  const auto requests = RequestsFromHttp(
      method, "application/json", R"([{"header": {"path": "a.stl", "total_size": "3"}, "data": "YWJj"}, {"data": "ZA=="}])");
  ASSERT_EQ(requests.size(), 2u);
  const auto first = Decode<v1::UploadFileChunk>(requests[0]);
  EXPECT_EQ(first.header().total_size(), 3u);
  EXPECT_EQ(first.data(), "abc");
  EXPECT_EQ(Decode<v1::UploadFileChunk>(requests[1]).data(), "d");
  ExpectError([&] { RequestsFromHttp(method, "application/json", R"({"data": "YWJj"})"); },
              ErrorCode::kInvalidArgument, {"JSON array"});
  ExpectError([&] { RequestsFromHttp(method, "application/json", R"([{"data": 5}])"); },
              ErrorCode::kInvalidArgument, {"request[0]"});
}

TEST(HttpJson, BadJsonAndUnknownFieldsAreRejectedNamingThem) {
  const auto& method = FindMethod("graspsim.v1.SceneService", "CreateScene");
  ExpectError([&] { RequestsFromHttp(method, "application/json", R"({"nmae": "x"})"); },
              ErrorCode::kInvalidArgument, {"graspsim.v1.CreateSceneRequest", "nmae"});
  ExpectError([&] { RequestsFromHttp(method, "application/json", R"({"name": )"); }, ErrorCode::kInvalidArgument,
              {"request"});
}

TEST(HttpJson, ResponsesUseProtoNamesAndPrintDefaults) {
  const auto& method = FindMethod("graspsim.v1.SceneService", "SetBodyPoses");
  v1::SetBodyPosesResponse response;
  response.set_revision(12);
  EXPECT_EQ(ResponseJson(method, Encode(response)), R"({"revision":"12"})");
  EXPECT_EQ(ResponseJson(method, Encode(v1::SetBodyPosesResponse())), R"({"revision":"0"})");
  v1::SceneSummary summary;
  summary.set_body_count(2);
  const std::string json = ResponseJson(FindMethod("graspsim.v1.SceneService", "GetScene"), Encode([&] {
                                          v1::Scene scene;
                                          *scene.mutable_summary() = summary;
                                          return scene;
                                        }()));
  EXPECT_NE(json.find(R"("body_count":2)"), std::string::npos) << json;
  EXPECT_NE(json.find(R"("tactile_arrays":[])"), std::string::npos) << json;
}

TEST(HttpJson, StatusesAndEnvelopes) {
  const grpc::Status status(grpc::StatusCode::INVALID_ARGUMENT, "pose: \"bad\"\n");
  EXPECT_EQ(StatusJson(status), R"({"code":3,"status":"INVALID_ARGUMENT","message":"pose: \"bad\"\n"})");
  EXPECT_EQ(EnvelopeJson(grpc::Status::OK, "response", "{}"), R"({"code":0,"status":"OK","message":"","response":{}})");
  EXPECT_EQ(HttpStatusFor(grpc::StatusCode::INVALID_ARGUMENT), 400);
  EXPECT_EQ(HttpStatusFor(grpc::StatusCode::NOT_FOUND), 404);
  EXPECT_EQ(HttpStatusFor(grpc::StatusCode::ALREADY_EXISTS), 409);
  EXPECT_EQ(HttpStatusFor(grpc::StatusCode::RESOURCE_EXHAUSTED), 429);
  EXPECT_EQ(HttpStatusFor(grpc::StatusCode::UNIMPLEMENTED), 501);
  EXPECT_EQ(HttpStatusFor(grpc::StatusCode::UNAUTHENTICATED), 401);
  EXPECT_EQ(HttpStatusFor(grpc::StatusCode::PERMISSION_DENIED), 403);
  EXPECT_EQ(HttpStatusFor(grpc::StatusCode::INTERNAL), 500);
}

TEST(HttpJson, QueryParameters) {
  EXPECT_EQ(ParseCount("max_messages", "3"), 3);
  ExpectError([] { ParseCount("max_messages", "-1"); }, ErrorCode::kInvalidArgument, {"max_messages", "-1"});
  ExpectError([] { ParseCount("max_messages", "2x"); }, ErrorCode::kInvalidArgument, {"'2x'"});
  EXPECT_DOUBLE_EQ(ParseSeconds("timeout_s", "0.25"), 0.25);
  ExpectError([] { ParseSeconds("timeout_s", "0"); }, ErrorCode::kInvalidArgument, {"timeout_s"});
  ExpectError([] { ParseSeconds("timeout_s", "inf"); }, ErrorCode::kInvalidArgument, {"timeout_s"});
}

TEST(HttpJson, ListsEveryApiMethod) {
  const std::string json = ListMethodsJson();
  for (const char* name : {"graspsim.v1.SceneService", "graspsim.v1.PerceptionService", "graspsim.v1.GraspService",
                           "graspsim.v1.TactileService", "graspsim.v1.GatewayService", "\"WatchScene\"",
                           "\"server_streaming\":true"}) {
    EXPECT_NE(json.find(name), std::string::npos) << name;
  }
}

}  // namespace
}  // namespace graspsim::rpc
