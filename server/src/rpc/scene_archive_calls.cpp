#include "rpc/scene_archive_calls.h"

#include <memory>

#include "core/error.h"
#include "persistence/scene_archive.h"
#include "rpc/call.h"
#include "rpc/convert.h"
#include "edits/scene_restore.h"
#include "rpc/scene_edits.h"

namespace graspsim::rpc {
namespace {

constexpr size_t kChunkBytes = 1 << 20;

// The archive is encoded on the worker pool (a scene with large files takes a while), then written chunk by chunk.
class ExportWriter : public grpc::ServerWriteReactor<v1::SceneArchiveChunk> {
 public:
  ExportWriter(grpc::CallbackServerContext* context, const v1::ExportSceneRequest* request, SceneRegistry* registry,
               WorkerPool* pool) {
    pool->Post([this, context, request, registry] {
      const grpc::Status status = Handle("ExportScene", *context, [&] {
        const auto scene = registry->Get(request->scene_id());
        id_ = scene->id();
        bytes_ = persistence::EncodeSceneArchive(edits::ArchiveOf(*scene));
      });
      if (!status.ok()) return Finish(status);
      Next();
    });
  }

  void OnWriteDone(bool ok) override {
    if (!ok) return Finish(grpc::Status(grpc::StatusCode::CANCELLED, "export cancelled"));
    Next();
  }
  void OnDone() override { delete this; }

 private:
  void Next() {
    if (offset_ >= bytes_.size() && offset_ > 0) return Finish(grpc::Status::OK);
    chunk_.Clear();
    if (offset_ == 0) chunk_.set_scene_id(id_);
    chunk_.set_data(bytes_.substr(offset_, kChunkBytes));
    offset_ += kChunkBytes;
    StartWrite(&chunk_);
  }

  std::string id_, bytes_;
  size_t offset_ = 0;
  v1::SceneArchiveChunk chunk_;
};

class ImportReader : public grpc::ServerReadReactor<v1::SceneArchiveChunk> {
 public:
  ImportReader(grpc::CallbackServerContext* context, SceneRegistry* registry, WorkerPool* pool, v1::Scene* response)
      : context_(context), registry_(registry), pool_(pool), response_(response) {
    StartRead(&chunk_);
  }

  void OnReadDone(bool ok) override {
    if (!ok) {  // the client half-closed: rebuild the scene off gRPC's threads
      pool_->Post([this] { Finish(Handle("ImportScene", *context_, [this] { Complete(); })); });
      return;
    }
    if (auto refused = RefusedCall(*context_)) return Finish(*refused);
    if (chunks_++ == 0) id_ = chunk_.scene_id();
    // Files, edits and state: an archive is at most the scene's file limit plus as much again for the rest.
    const uint64_t limit = 2 * registry_->limits().max_scene_file_bytes;
    if (bytes_.size() + chunk_.data().size() > limit) {
      const grpc::Status status(grpc::StatusCode::RESOURCE_EXHAUSTED,
                                "data: the archive exceeds " + std::to_string(limit) +
                                    " bytes (twice --max-scene-file-bytes)");
      LogRequest("ImportScene", *context_, status, {});
      return Finish(status);
    }
    bytes_ += chunk_.data();
    StartRead(&chunk_);
  }

  void OnDone() override { delete this; }

 private:
  void Complete() {
    const persistence::SceneArchive archive = persistence::DecodeSceneArchive(bytes_, "data");
    bytes_.clear();
    ToProto(edits::ImportArchive(archive, id_, registry_, LegacyEditReaderFor(registry_->limits()))->View(), false, response_);
  }

  grpc::CallbackServerContext* const context_;
  SceneRegistry* const registry_;
  WorkerPool* const pool_;
  v1::Scene* const response_;
  v1::SceneArchiveChunk chunk_;
  std::string id_, bytes_;
  size_t chunks_ = 0;
};

}  // namespace

grpc::ServerWriteReactor<v1::SceneArchiveChunk>* StartExport(grpc::CallbackServerContext* context,
                                                             const v1::ExportSceneRequest* request,
                                                             SceneRegistry* registry, WorkerPool* pool) {
  return new ExportWriter(context, request, registry, pool);
}

grpc::ServerReadReactor<v1::SceneArchiveChunk>* StartImport(grpc::CallbackServerContext* context,
                                                            SceneRegistry* registry, WorkerPool* pool,
                                                            v1::Scene* response) {
  return new ImportReader(context, registry, pool, response);
}

}  // namespace graspsim::rpc
