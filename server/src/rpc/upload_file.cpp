#include "rpc/upload_file.h"

#include "core/error.h"
#include "core/sha256.h"
#include "core/validate.h"
#include "rpc/call.h"

namespace graspsim::rpc {
namespace {

class UploadReactor : public grpc::ServerReadReactor<v1::UploadFileChunk> {
 public:
  UploadReactor(grpc::CallbackServerContext* context, SceneRegistry* registry, WorkerPool* pool,
                v1::FileInfo* response)
      : context_(context), registry_(registry), pool_(pool), response_(response) {
    StartRead(&chunk_);
  }

  void OnReadDone(bool ok) override {
    if (!ok) {  // the client half-closed: check and store the whole file off gRPC's threads
      pool_->Post([this] { Finish(Handle("UploadFile", *context_, [this] { Complete(); })); });
      return;
    }
    if (auto refused = RefusedCall(*context_)) return Finish(*refused);  // checked on the header chunk
    try {
      Append();
    } catch (const Error& error) {
      // Refused at once: the rest of the stream is not read.
      const grpc::Status status = ToStatus(error);
      LogRequest("UploadFile", *context_, status, {});
      Finish(status);
      return;
    }
    chunk_.Clear();
    StartRead(&chunk_);
  }

  void OnDone() override { delete this; }

 private:
  void Append() {
    if (!scene_) {
      if (!chunk_.has_header()) ThrowInvalidArgument("header: the first chunk of an upload must carry the header");
      header_ = chunk_.header();
      scene_ = registry_->Get(header_.scene_id());
      CheckRelativePath("header.path", header_.path());
      const uint64_t limit = registry_->limits().max_upload_bytes;
      if (header_.total_size() > limit) {
        ThrowResourceExhausted("header.total_size: " + std::to_string(header_.total_size()) +
                               " bytes is above the upload limit of " + std::to_string(limit));
      }
      const std::string& sha = header_.sha256();
      if (sha.size() != 64 || sha.find_first_not_of("0123456789abcdef") != std::string::npos) {
        ThrowInvalidArgument("header.sha256: '" + sha.substr(0, 80) + "' is not 64 lowercase hex digits");
      }
      bytes_ = std::make_shared<std::string>();
      bytes_->reserve(header_.total_size());
    } else if (chunk_.has_header()) {
      ThrowInvalidArgument("header: sent again in a later chunk");
    }
    if (bytes_->size() + chunk_.data().size() > header_.total_size()) {
      ThrowInvalidArgument("data: more than header.total_size = " + std::to_string(header_.total_size()) +
                           " bytes received");
    }
    bytes_->append(chunk_.data());
  }

  void Complete() {
    if (!scene_) ThrowInvalidArgument("header: the upload carried no chunk");
    if (bytes_->size() != header_.total_size()) {
      ThrowInvalidArgument("header.total_size: " + std::to_string(header_.total_size()) + " bytes announced, " +
                           std::to_string(bytes_->size()) + " received");
    }
    const std::string actual = Sha256Hex(*bytes_);
    if (actual != header_.sha256()) {
      ThrowInvalidArgument("header.sha256: " + header_.sha256() + " announced, the received bytes hash to " + actual);
    }
    // One journal transaction holds the whole file (scene_store.h): it is stored whole or not at all.
    SceneOp op;
    op.kind = "UploadFile";
    op.path = header_.path();
    op.sha256 = actual;
    op.file = bytes_;
    scene_->PutFile(header_.path(), bytes_, actual, &op);
    response_->set_path(header_.path());
    response_->set_size(bytes_->size());
    response_->set_sha256(actual);
  }

  grpc::CallbackServerContext* const context_;
  SceneRegistry* const registry_;
  WorkerPool* const pool_;
  v1::FileInfo* const response_;
  v1::UploadFileChunk chunk_;
  v1::UploadFileHeader header_;
  std::shared_ptr<Scene> scene_;
  std::shared_ptr<std::string> bytes_;
};

}  // namespace

grpc::ServerReadReactor<v1::UploadFileChunk>* StartUpload(grpc::CallbackServerContext* context,
                                                          SceneRegistry* registry, WorkerPool* pool,
                                                          v1::FileInfo* response) {
  return new UploadReactor(context, registry, pool, response);
}

}  // namespace graspsim::rpc
