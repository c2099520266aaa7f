#include "recording/recorders.h"

#include <algorithm>
#include <cctype>
#include <chrono>
#include <ctime>
#include <filesystem>
#include <set>

#include "core/durable_files.h"
#include "core/error.h"
#include "core/log.h"

namespace graspsim::recording {
namespace {

namespace fs = std::filesystem;

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

}  // namespace

struct Recorders::Active {
  std::string name, path, ros2_path, scene_id;
  std::shared_ptr<FrameTap> tap;
  RecordingSession* session = nullptr;  // owned by the tap

  RecordingInfo Info(bool active) const {
    return {name, scene_id, path, ros2_path, active, tap->frames(), tap->dropped(), session->messages(),
            session->bytes(), session->start_time(), session->end_time()};
  }
};

Recorders::Recorders(std::string directory) : directory_(std::move(directory)) {
  if (!directory_.empty()) CreateDirectoriesDurably("recording directory ", directory_);
}

Recorders::~Recorders() { StopAll(); }

void Recorders::StopAll() {
  std::map<std::string, std::shared_ptr<Active>> active;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    active.swap(active_);
  }
  for (auto& [id, recording] : active) recording->tap->Stop();
}

void Recorders::ReapLocked() {
  for (auto it = active_.begin(); it != active_.end();) {
    if (!it->second->tap->finished()) {
      ++it;
      continue;
    }
    it->second->tap->Stop();
    finished_[it->second->name] = it->second->Info(false);
    it = active_.erase(it);
  }
}

std::string Recorders::ActiveSceneOf(const std::string& name) {
  std::lock_guard<std::mutex> lock(mutex_);
  ReapLocked();
  for (const auto& [id, active] : active_) {
    if (active->name == name) return id;
  }
  return "";
}

bool Recorders::WithSession(const std::string& scene_id, const std::function<void(RecordingSession&)>& use) {
  std::shared_ptr<Active> active;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    auto it = active_.find(scene_id);
    if (it == active_.end()) return false;
    active = it->second;
  }
  use(*active->session);
  return true;
}

std::string Recorders::PathOf(const std::string& field, const std::string& name) const {
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

RecordingInfo Recorders::Start(const std::shared_ptr<Scene>& scene, const RecordingRequest& request,
                               const FrameEncoderFactory& encoder) {
  const std::string name = request.name.empty() ? scene->id() + "-" + UtcStamp() + ".mcap" : request.name;
  SessionOptions options;
  options.path = PathOf("name", name);
  options.compression = request.compression;
  options.force_torque_joints = request.force_torque_joints;
  const double rate = request.rate_hz == 0 ? 30 : request.rate_hz;
  if (!(rate > 0 && rate <= 1000)) ThrowInvalidArgument("rate_hz: " + std::to_string(request.rate_hz) + " is outside (0, 1000]");
  double scene_time = 0;
  scene->Read([&](const SceneModel& model, const SceneState& state, uint64_t) {
    scene_time = state.time;
    for (const std::string& joint : options.force_torque_joints) {
      if (!model.joint_index.count(joint)) ThrowNotFound("force_torque_joints: no joint '" + joint + "' in the scene");
    }
  });
  if (request.ros2) options.ros2_path = Ros2PathOf(options.path);

  std::lock_guard<std::mutex> lock(mutex_);
  ReapLocked();
  if (auto it = active_.find(scene->id()); it != active_.end()) {
    throw Error(ErrorCode::kAlreadyExists, "scene_id: scene '" + scene->id() + "' is already being recorded to '" +
                                               it->second->name + "'; stop that recording first");
  }
  if (fs::exists(options.path) || (!options.ros2_path.empty() && fs::exists(options.ros2_path))) {
    throw Error(ErrorCode::kAlreadyExists, "name: a recording '" + name + "' exists; choose another name");
  }
  auto session = std::make_unique<RecordingSession>(options, scene_time, encoder);
  auto active = std::make_shared<Active>();
  active->name = name;
  active->path = options.path;
  active->ros2_path = options.ros2_path;
  active->scene_id = scene->id();
  active->session = session.get();
  active->tap = std::make_shared<FrameTap>(scene, std::move(session), 1.0 / rate);
  active->tap->Start();
  active_[scene->id()] = active;
  Log(LogLevel::kInfo, "recording started", {{"scene", scene->id()}, {"path", options.path}});
  return active->Info(true);
}

void Recorders::StartAutomatically(const std::shared_ptr<Scene>& scene, const FrameEncoderFactory& encoder) {
  try {
    Start(scene, RecordingRequest{}, encoder);
  } catch (const Error& error) {
    Log(LogLevel::kError, "cannot record", {{"scene", scene->id()}, {"error", error.what()}});
  }
}

RecordingInfo Recorders::Stop(const std::string& scene_id) {
  std::shared_ptr<Active> active;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    auto it = active_.find(scene_id);
    if (it == active_.end()) ThrowNotFound("scene_id: scene '" + scene_id + "' is not being recorded");
    active = it->second;
    active_.erase(it);
  }
  const std::string error = active->tap->Stop();
  const RecordingInfo info = active->Info(false);
  {
    std::lock_guard<std::mutex> lock(mutex_);
    finished_[active->name] = info;
  }
  if (!error.empty()) throw Error(ErrorCode::kInternal, "recording '" + active->name + "' failed: " + error);
  Log(LogLevel::kInfo, "recording stopped", {{"scene", active->scene_id}, {"path", active->path},
                                             {"frames", std::to_string(info.frames)}});
  return info;
}

std::vector<RecordingInfo> Recorders::List() {
  std::lock_guard<std::mutex> lock(mutex_);
  ReapLocked();
  std::vector<RecordingInfo> out;
  std::set<std::string> listed;
  for (const auto& [id, active] : active_) {
    out.push_back(active->Info(true));
    listed.insert(active->name);
  }
  if (directory_.empty()) return out;
  std::vector<fs::path> files;
  for (const auto& entry : fs::directory_iterator(directory_)) {
    if (entry.path().extension() == ".mcap" && !listed.count(entry.path().filename().string())) files.push_back(entry.path());
  }
  std::sort(files.begin(), files.end());
  // Files this server finished carry their figures; older ones (before a restart) their name and size.
  for (const auto& file : files) {
    RecordingInfo& info = out.emplace_back();
    if (auto it = finished_.find(file.filename().string()); it != finished_.end()) info = it->second;
    info.name = file.filename().string();
    info.path = file.string();
    if (fs::exists(Ros2PathOf(file.string()))) info.ros2_path = Ros2PathOf(file.string());
    info.bytes = fs::file_size(file);
    info.active = false;
  }
  return out;
}

}  // namespace graspsim::recording
