#include "rpc/recording_service.h"

#include <algorithm>
#include <chrono>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <set>

#include "core/log.h"
#include "rpc/call.h"
#include "rpc/failed_call.h"
#include "rpc/recording_session.h"

namespace graspsim::rpc {
namespace {

namespace fs = std::filesystem;
constexpr size_t kDownloadChunk = 1 << 20;

bool IsPlainName(const std::string& name) {
  if (name.empty() || name.size() > 200 || name.front() == '.') return false;
  for (char c : name) {
    if (!std::isalnum(static_cast<unsigned char>(c)) && c != '-' && c != '_' && c != '.') return false;
  }
  return true;
}

std::string UtcStamp() {
  const std::time_t now = std::chrono::system_clock::to_time_t(std::chrono::system_clock::now());
  std::tm utc{};
  gmtime_r(&now, &utc);
  char text[32];
  std::strftime(text, sizeof(text), "%Y%m%dT%H%M%SZ", &utc);
  return text;
}

std::string Ros2PathOf(const std::string& path) { return path.substr(0, path.size() - 5) + ".ros2"; }

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


}  // namespace

struct RecordingServiceImpl::Active {
  std::string name, path, ros2_path, scene_id;
  std::shared_ptr<recording::FrameTap> tap;
  RecordingSession* session = nullptr;  // owned by the tap

  void ToProto(bool active, v1::Recording* out) const {
    out->set_name(name);
    out->set_scene_id(scene_id);
    out->set_path(path);
    out->set_ros2_path(ros2_path);
    out->set_active(active);
    out->set_frames(tap->frames());
    out->set_dropped_frames(tap->dropped());
    out->set_messages(session->messages());
    out->set_bytes(session->bytes());
    out->set_start_time(session->start_time());
    out->set_end_time(session->end_time());
  }
};


RecordingServiceImpl::RecordingServiceImpl(SceneRegistry* registry, WorkerPool* pool, std::string directory)
    : registry_(registry), pool_(pool), directory_(std::move(directory)) {
  if (!directory_.empty()) fs::create_directories(directory_);
}

RecordingServiceImpl::~RecordingServiceImpl() { StopAll(); }

void RecordingServiceImpl::StopAll() {
  std::map<std::string, std::shared_ptr<Active>> active;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    active.swap(active_);
  }
  for (auto& [id, recording] : active) recording->tap->Stop();
}

std::shared_ptr<RecordingServiceImpl::Active> RecordingServiceImpl::ActiveOf(const std::string& scene_id) {
  std::lock_guard<std::mutex> lock(mutex_);
  auto it = active_.find(scene_id);
  return it == active_.end() ? nullptr : it->second;
}

void RecordingServiceImpl::Append(const std::string& scene_id, const std::string& topic,
                                  const google::protobuf::Message& message) {
  if (auto active = ActiveOf(scene_id)) {
    try {
      active->session->Append(topic, message);
    } catch (const std::exception& error) {
      Log(LogLevel::kError, "recording cannot take a message", {{"scene", scene_id}, {"topic", topic}, {"error", error.what()}});
    }
  }
}

void RecordingServiceImpl::AppendPointCloud(const std::string& scene_id, const std::string& topic,
                                            const std::vector<Vec3>& points) {
  if (auto active = ActiveOf(scene_id)) {
    try {
      active->session->AppendPointCloud(topic, points);
    } catch (const std::exception& error) {
      Log(LogLevel::kError, "recording cannot take a point cloud", {{"scene", scene_id}, {"topic", topic}, {"error", error.what()}});
    }
  }
}

std::string RecordingServiceImpl::ActiveSceneOfLocked(const std::string& name) {
  ReapLocked();
  for (const auto& [id, active] : active_) {
    if (active->name == name) return id;
  }
  return "";
}

void RecordingServiceImpl::ReapLocked() {
  for (auto it = active_.begin(); it != active_.end();) {
    if (!it->second->tap->finished()) {
      ++it;
      continue;
    }
    it->second->tap->Stop();
    it->second->ToProto(false, &finished_[it->second->name]);
    it = active_.erase(it);
  }
}

std::string RecordingServiceImpl::PathOf(const std::string& field, const std::string& name) const {
  if (directory_.empty()) {
    throw Error(ErrorCode::kFailedPrecondition,
                "recordings are off: start the server with --record DIR, --recording-dir DIR or a --data-dir");
  }
  if (!IsPlainName(name) || name.size() < 6 || name.substr(name.size() - 5) != ".mcap") {
    ThrowInvalidArgument(field + ": '" + name.substr(0, 80) +
                         "' is not a recording name (letters, digits, '-', '_', '.', ending in .mcap, no directories)");
  }
  return directory_ + "/" + name;
}

void RecordingServiceImpl::Start(const std::shared_ptr<Scene>& scene, const v1::StartRecordingRequest& request,
                                 v1::Recording* out) {
  const std::string name = request.name().empty() ? scene->id() + "-" + UtcStamp() + ".mcap" : request.name();
  RecordingOptions options;
  options.path = PathOf("name", name);
  options.groups = ParseChannelGroups("groups", {request.groups().begin(), request.groups().end()});
  options.compression = recording::ParseCompression(request.compression(), "compression");
  options.force_torque_joints.assign(request.force_torque_joints().begin(), request.force_torque_joints().end());
  const double rate = request.rate_hz() == 0 ? 30 : request.rate_hz();
  if (!(rate > 0 && rate <= 1000)) ThrowInvalidArgument("rate_hz: " + std::to_string(request.rate_hz()) + " is outside (0, 1000]");
  options.interval = 1.0 / rate;
  double scene_time = 0;
  scene->Read([&](const SceneModel& model, const SceneState& state, uint64_t) {
    scene_time = state.time;
    for (const std::string& joint : options.force_torque_joints) {
      if (!model.joint_index.count(joint)) ThrowNotFound("force_torque_joints: no joint '" + joint + "' in the scene");
    }
  });
  if (options.groups.ros2) options.ros2_path = Ros2PathOf(options.path);

  std::lock_guard<std::mutex> lock(mutex_);
  ReapLocked();
  if (auto it = active_.find(scene->id()); it != active_.end()) {
    throw Error(ErrorCode::kAlreadyExists, "scene_id: scene '" + scene->id() + "' is already being recorded to '" +
                                               it->second->name + "'; stop that recording first");
  }
  if (fs::exists(options.path) || (!options.ros2_path.empty() && fs::exists(options.ros2_path))) {
    throw Error(ErrorCode::kAlreadyExists, "name: a recording '" + name + "' exists; choose another name");
  }
  auto session = std::make_unique<RecordingSession>(options, scene_time);
  auto active = std::make_shared<Active>();
  active->name = name;
  active->path = options.path;
  active->ros2_path = options.ros2_path;
  active->scene_id = scene->id();
  active->session = session.get();
  active->tap = std::make_shared<recording::FrameTap>(scene, std::move(session), options.interval);
  active->tap->Start();
  active_[scene->id()] = active;
  active->ToProto(true, out);
  Log(LogLevel::kInfo, "recording started", {{"scene", scene->id()}, {"path", options.path}});
}

void RecordingServiceImpl::RecordAutomatically(const std::shared_ptr<Scene>& scene) {
  v1::StartRecordingRequest request;
  v1::Recording ignored;
  try {
    Start(scene, request, &ignored);
  } catch (const Error& error) {
    Log(LogLevel::kError, "cannot record", {{"scene", scene->id()}, {"error", error.what()}});
  }
}

grpc::ServerUnaryReactor* RecordingServiceImpl::StartRecording(Context* context, const v1::StartRecordingRequest* request,
                                                               v1::Recording* response) {
  return RunUnary(context, "RecordingService/StartRecording", pool_, [=, this] {
    Start(registry_->Get(request->scene_id()), *request, response);
  });
}

grpc::ServerUnaryReactor* RecordingServiceImpl::StopRecording(Context* context, const v1::StopRecordingRequest* request,
                                                              v1::Recording* response) {
  return RunUnary(context, "RecordingService/StopRecording", pool_, [=, this] {
    std::shared_ptr<Active> active;
    {
      std::lock_guard<std::mutex> lock(mutex_);
      auto it = active_.find(request->scene_id());
      if (it == active_.end()) ThrowNotFound("scene_id: scene '" + request->scene_id() + "' is not being recorded");
      active = it->second;
      active_.erase(it);
    }
    const std::string error = active->tap->Stop();
    active->ToProto(false, response);
    {
      std::lock_guard<std::mutex> lock(mutex_);
      finished_[active->name] = *response;
    }
    if (!error.empty()) throw Error(ErrorCode::kInternal, "recording '" + active->name + "' failed: " + error);
    Log(LogLevel::kInfo, "recording stopped", {{"scene", active->scene_id}, {"path", active->path},
                                               {"frames", std::to_string(response->frames())}});
  });
}

grpc::ServerUnaryReactor* RecordingServiceImpl::ListRecordings(Context* context, const v1::ListRecordingsRequest*,
                                                               v1::ListRecordingsResponse* response) {
  return RunUnary(context, "RecordingService/ListRecordings", pool_, [=, this] {
    std::lock_guard<std::mutex> lock(mutex_);
    ReapLocked();
    std::set<std::string> listed;
    for (const auto& [id, active] : active_) {
      active->ToProto(true, response->add_recordings());
      listed.insert(active->name);
    }
    if (directory_.empty()) return;
    std::vector<fs::path> files;
    for (const auto& entry : fs::directory_iterator(directory_)) {
      if (entry.path().extension() == ".mcap" && !listed.count(entry.path().filename().string())) files.push_back(entry.path());
    }
    std::sort(files.begin(), files.end());
    // Files this server finished carry their figures; older ones (before a restart) their name and size.
    for (const auto& file : files) {
      v1::Recording* out = response->add_recordings();
      if (auto it = finished_.find(file.filename().string()); it != finished_.end()) *out = it->second;
      out->set_name(file.filename().string());
      out->set_path(file.string());
      if (fs::exists(Ros2PathOf(file.string()))) out->set_ros2_path(Ros2PathOf(file.string()));
      out->set_bytes(fs::file_size(file));
      out->set_active(false);
    }
  });
}

grpc::ServerWriteReactor<v1::RecordingChunk>* RecordingServiceImpl::DownloadRecording(
    Context* context, const v1::DownloadRecordingRequest* request) {
  std::string path;
  return StartStream<v1::RecordingChunk>(
      "RecordingService/DownloadRecording", context, [&] { path = PathOf("name", request->name()); },
      [&] { return new FileDownload(path); });
}

}  // namespace graspsim::rpc
