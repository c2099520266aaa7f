// Chunked upload reassembly (rpc/upload_file.cpp, SceneService.UploadFile) through the real reactor: one
// graspsim server in this process (loopback, scenes in memory, no HTTP), a fresh scene per input, the input's
// chunks streamed to it, the scene deleted afterwards (so an input's outcome does not depend on earlier ones).
//
// Input: a flags byte, then chunks, each a length byte and that many bytes parsed as an UploadFileChunk (a chunk
// that does not parse is sent empty). Flags help the fuzzer past what it cannot guess:
//   bit 0: the first chunk's header names the live scene      bit 1: header.sha256 = the hash of all data sent
//   bit 2: header.total_size = the bytes sent                   bit 3: the client cancels instead of half-closing
#include <memory>

#include <grpcpp/grpcpp.h>

#include "core/log.h"
#include "core/sha256.h"
#include "fuzz_common.h"
#include "graspsim/v1/scene.grpc.pb.h"
#include "rpc/server.h"

namespace {

namespace v1 = graspsim::v1;

struct Harness {
  Harness() {
    graspsim::SetLogLevel(graspsim::LogLevel::kError);  // every refused upload would log a line
    graspsim::rpc::ServerOptions options;
    options.listen = "127.0.0.1:0";
    options.http_enabled = false;
    options.data_dir = "off";
    options.grasp_data_dir = "off";
    options.auth_data_dir = "off";
    options.worker_threads = 2;
    options.limits.max_upload_bytes = 1 << 16;  // the checks are the same; the fuzzer's allocations stay small
    options.limits.max_scene_file_bytes = 1 << 20;
    server = std::make_unique<graspsim::rpc::GraspsimServer>(options);
    stub = v1::SceneService::NewStub(grpc::CreateChannel("127.0.0.1:" + std::to_string(server->port()),
                                                         grpc::InsecureChannelCredentials()));
  }
  std::unique_ptr<graspsim::rpc::GraspsimServer> server;
  std::unique_ptr<v1::SceneService::Stub> stub;
};

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size < 1) return 0;
  static Harness* harness = new Harness;  // lives for the process: one server, many inputs
  const uint8_t flags = data[0];
  std::vector<v1::UploadFileChunk> chunks;
  for (size_t at = 1; at < size;) {
    const size_t n = std::min<size_t>(data[at], size - at - 1);
    v1::UploadFileChunk chunk;
    if (!chunk.ParseFromArray(data + at + 1, int(n))) chunk.Clear();
    chunks.push_back(std::move(chunk));
    at += 1 + n;
  }

  v1::Scene scene;
  {
    grpc::ClientContext context;
    v1::CreateSceneRequest request;
    request.set_name("fuzz");
    if (!harness->stub->CreateScene(&context, request, &scene).ok()) graspsim::fuzz::Broken("CreateScene failed");
  }
  std::string all;
  for (const auto& chunk : chunks) all += chunk.data();
  if (!chunks.empty()) {
    auto* header = chunks.front().mutable_header();
    if (flags & 1) header->set_scene_id(scene.summary().id());
    if (flags & 2) header->set_sha256(graspsim::Sha256Hex(all));
    if (flags & 4) header->set_total_size(all.size());
  }
  {
    grpc::ClientContext context;
    v1::FileInfo info;
    auto writer = harness->stub->UploadFile(&context, &info);
    for (const auto& chunk : chunks) {
      if (!writer->Write(chunk)) break;  // refused: the server ended the call
    }
    if (flags & 8) {
      context.TryCancel();
    } else {
      writer->WritesDone();
    }
    const grpc::Status status = writer->Finish();
    if (status.ok() && (info.size() != all.size() || info.sha256() != graspsim::Sha256Hex(all))) {
      graspsim::fuzz::Broken("UploadFile acknowledged a file other than the bytes sent");
    }
  }
  {
    grpc::ClientContext context;
    v1::DeleteSceneRequest request;
    request.set_scene_id(scene.summary().id());
    v1::DeleteSceneResponse response;
    harness->stub->DeleteScene(&context, request, &response);
  }
  return 0;
}
