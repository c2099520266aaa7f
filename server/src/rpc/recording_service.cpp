#include "rpc/recording_service.h"

#include <filesystem>
#include <fstream>

#include "core/log.h"
#include "rpc/call.h"
#include "rpc/failed_call.h"
#include "rpc/recording_channels.h"

namespace graspsim::rpc {
namespace {

namespace fs = std::filesystem;
constexpr size_t kDownloadChunk = 1 << 20;

class FileDownload : public grpc::ServerWriteReactor<v1::RecordingChunk> {
 public:
  explicit FileDownload(const std::string& path) : in_(path, std::ios::binary) {
    if (!in_) {
      Finish(grpc::Status(grpc::StatusCode::NOT_FOUND, "name: no recording '" + fs::path(path).filename().string() + "'"));
      return;
    }
    Next();
  }
  void OnWriteDone(bool ok) override {
    if (!ok) return Finish(grpc::Status(grpc::StatusCode::CANCELLED, "download cancelled"));
    Next();
  }
  void OnDone() override { delete this; }

 private:
  void Next() {
    std::string data(kDownloadChunk, '\0');
    in_.read(data.data(), static_cast<std::streamsize>(data.size()));
    data.resize(static_cast<size_t>(in_.gcount()));
    if (data.empty()) return Finish(grpc::Status::OK);
    chunk_.set_offset(offset_);
    offset_ += data.size();
    chunk_.set_data(std::move(data));
    StartWrite(&chunk_);
  }
  std::ifstream in_;
  v1::RecordingChunk chunk_;
  uint64_t offset_ = 0;
};

// A recording's MCAP channels: the API's messages and Foxglove's, as the request's groups say.
recording::FrameEncoderFactory Encoder(ChannelGroups groups, std::vector<std::string> force_torque_joints) {
  return [groups, joints = std::move(force_torque_joints)](recording::ChannelWriter* file) {
    return std::make_unique<ProtobufChannels>(file, groups, joints);
  };
}

void ToProto(const recording::RecordingInfo& info, v1::Recording* out) {
  out->set_name(info.name);
  out->set_scene_id(info.scene_id);
  out->set_path(info.path);
  out->set_ros2_path(info.ros2_path);
  out->set_active(info.active);
  out->set_frames(info.frames);
  out->set_dropped_frames(info.dropped_frames);
  out->set_messages(info.messages);
  out->set_bytes(info.bytes);
  out->set_start_time(info.start_time);
  out->set_end_time(info.end_time);
}

}  // namespace

RecordingServiceImpl::RecordingServiceImpl(SceneRegistry* registry, WorkerPool* pool, std::string directory)
    : registry_(registry), pool_(pool), recorders_(std::move(directory)), replays_(&recorders_, registry, ReplayCodecOf()) {}

void RecordingServiceImpl::RecordAutomatically(const std::shared_ptr<Scene>& scene) {
  recorders_.StartAutomatically(scene, Encoder(ChannelGroups{}, {}));
}

void RecordingServiceImpl::Append(const std::string& scene_id, const std::string& topic,
                                  const google::protobuf::Message& message) {
  try {
    recorders_.WithSession(scene_id, [&](recording::RecordingSession& session) {
      session.Append([&](recording::FrameEncoder& encoder, double time) {
        // Every session of this service has its channels from Encoder.
        static_cast<ProtobufChannels&>(encoder).WriteMessage(topic, time, message);
      });
    });
  } catch (const std::exception& error) {
    Log(LogLevel::kError, "recording cannot take a message", {{"scene", scene_id}, {"topic", topic}, {"error", error.what()}});
  }
}

void RecordingServiceImpl::AppendPointCloud(const std::string& scene_id, const std::string& topic,
                                            const std::vector<Vec3>& points) {
  try {
    recorders_.WithSession(scene_id, [&](recording::RecordingSession& session) { session.AppendPointCloud(topic, points); });
  } catch (const std::exception& error) {
    Log(LogLevel::kError, "recording cannot take a point cloud", {{"scene", scene_id}, {"topic", topic}, {"error", error.what()}});
  }
}

grpc::ServerUnaryReactor* RecordingServiceImpl::StartRecording(Context* context, const v1::StartRecordingRequest* request,
                                                               v1::Recording* response) {
  return RunUnary(context, "RecordingService/StartRecording", pool_, [=, this] {
    const std::shared_ptr<Scene> scene = registry_->Get(request->scene_id());
    recording::RecordingRequest start;
    start.name = request->name();
    const ChannelGroups groups = ParseChannelGroups("groups", {request->groups().begin(), request->groups().end()});
    start.ros2 = groups.ros2;
    start.compression = recording::ParseCompression(request->compression(), "compression");
    start.force_torque_joints.assign(request->force_torque_joints().begin(), request->force_torque_joints().end());
    start.rate_hz = request->rate_hz();
    ToProto(recorders_.Start(scene, start, Encoder(groups, start.force_torque_joints)), response);
  });
}

grpc::ServerUnaryReactor* RecordingServiceImpl::StopRecording(Context* context, const v1::StopRecordingRequest* request,
                                                              v1::Recording* response) {
  return RunUnary(context, "RecordingService/StopRecording", pool_, [=, this] {
    ToProto(recorders_.Stop(request->scene_id()), response);
  });
}

grpc::ServerUnaryReactor* RecordingServiceImpl::ListRecordings(Context* context, const v1::ListRecordingsRequest*,
                                                               v1::ListRecordingsResponse* response) {
  return RunUnary(context, "RecordingService/ListRecordings", pool_, [=, this] {
    for (const recording::RecordingInfo& info : recorders_.List()) ToProto(info, response->add_recordings());
  });
}

grpc::ServerWriteReactor<v1::RecordingChunk>* RecordingServiceImpl::DownloadRecording(
    Context* context, const v1::DownloadRecordingRequest* request) {
  std::string path;
  return StartStream<v1::RecordingChunk>(
      "RecordingService/DownloadRecording", context, [&] { path = recorders_.PathOf("name", request->name()); },
      [&] { return new FileDownload(path); });
}

}  // namespace graspsim::rpc
