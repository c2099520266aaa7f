// The HTTP/JSON mapping (rpc/http_json.h) as the gateway's POST /v1/<Service>/<Method> handler uses it: the
// first byte picks one of the API's methods (unary and client-streaming alike), the second the Content-Type
// (JSON, form, none, other), the rest is the body: RequestsFromHttp must give messages that parse as the method's
// request type, or throw Error. The same body is also fed to the handler's other parsers (FindMethod on a
// "Service/Method" split, ParseCount and ParseSeconds of the query parameters) and to JsonString, whose output
// must parse back as JSON to the same text.
#include <google/protobuf/descriptor.h>
#include <google/protobuf/struct.pb.h>
#include <google/protobuf/util/json_util.h>

#include "fuzz_common.h"
#include "graspsim/v1/auth.pb.h"
#include "graspsim/v1/gateway.pb.h"
#include "graspsim/v1/grasp.pb.h"
#include "graspsim/v1/perception.pb.h"
#include "graspsim/v1/scene.pb.h"
#include "graspsim/v1/tactile.pb.h"
#include "rpc/http_json.h"

namespace pb = google::protobuf;

namespace {

std::vector<const pb::MethodDescriptor*> AllMethods() {
  std::vector<const pb::MethodDescriptor*> methods;
  for (const pb::FileDescriptor* file :
       {graspsim::v1::Scene::descriptor()->file(), graspsim::v1::CompleteShapeRequest::descriptor()->file(),
        graspsim::v1::PlanGraspsRequest::descriptor()->file(), graspsim::v1::SampleRequest::descriptor()->file(),
        graspsim::v1::ListDevicesRequest::descriptor()->file(), graspsim::v1::AddTokenRequest::descriptor()->file()}) {
    for (int s = 0; s < file->service_count(); ++s) {
      for (int m = 0; m < file->service(s)->method_count(); ++m) methods.push_back(file->service(s)->method(m));
    }
  }
  return methods;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size < 2) return 0;
  static const std::vector<const pb::MethodDescriptor*> methods = AllMethods();
  static const char* const kContentTypes[] = {"application/json", "application/x-www-form-urlencoded", "",
                                              "text/plain; charset=utf-8"};
  const pb::MethodDescriptor& method = *methods[data[0] % methods.size()];
  const std::string content_type = kContentTypes[data[1] % 4];
  const std::string body = graspsim::fuzz::Text(data + 2, size - 2);

  graspsim::fuzz::Rejects([&] {
    for (const grpc::ByteBuffer& buffer : graspsim::rpc::RequestsFromHttp(method, content_type, body)) {
      std::vector<grpc::Slice> slices;
      if (!buffer.Dump(&slices).ok()) graspsim::fuzz::Broken("RequestsFromHttp: a buffer that cannot be read");
      std::string bytes;
      for (const grpc::Slice& slice : slices) bytes.append(reinterpret_cast<const char*>(slice.begin()), slice.size());
      std::unique_ptr<pb::Message> message(pb::MessageFactory::generated_factory()
                                               ->GetPrototype(method.input_type())->New());
      if (!message->ParseFromString(bytes)) graspsim::fuzz::Broken("RequestsFromHttp: a request that does not parse");
    }
  });
  const size_t slash = body.find('/');
  if (slash != std::string::npos) {
    graspsim::fuzz::Rejects([&] { graspsim::rpc::FindMethod(body.substr(0, slash), body.substr(slash + 1)); });
  }
  graspsim::fuzz::Rejects([&] { graspsim::rpc::ParseCount("max_messages", body); });
  graspsim::fuzz::Rejects([&] { graspsim::rpc::ParseSeconds("timeout_s", body); });

  // JsonString: a JSON string literal of any bytes that are valid UTF-8 reads back as the same text.
  const std::string literal = graspsim::rpc::JsonString(body);
  pb::Value value;
  if (pb::util::JsonStringToMessage(literal, &value).ok() && value.string_value() != body) {
    graspsim::fuzz::Broken("JsonString: the literal reads back as other text");
  }
  return 0;
}
