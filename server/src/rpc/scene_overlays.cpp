#include "rpc/scene_overlays.h"

#include <algorithm>

#include "rpc/http_json.h"

namespace graspsim::rpc {
namespace {

// Scenes whose overlays are kept; the oldest-changed goes first (a long-running server creates many scenes).
constexpr size_t kMaxScenes = 1024;

// 9 digits: nanometres at a metre, and the plan's duration to 1e-9 relative.
std::string Number(double value) { return JsonNumber(value, 9); }

std::string PointJson(const SceneOverlays::Point& p) {
  return "[" + Number(p[0]) + "," + Number(p[1]) + "," + Number(p[2]) + "]";
}

}  // namespace

SceneOverlays::Entry& SceneOverlays::Touch(const std::string& scene_id) {
  if (entries_.size() >= kMaxScenes && !entries_.count(scene_id)) {
    entries_.erase(std::min_element(entries_.begin(), entries_.end(), [](const auto& a, const auto& b) {
      return a.second.version < b.second.version;
    }));
  }
  Entry& entry = entries_[scene_id];
  entry.version = ++version_;
  return entry;
}

void SceneOverlays::SetCompletion(const std::string& scene_id, Completion completion) {
  std::lock_guard lock(mutex_);
  Entry& entry = Touch(scene_id);
  entry.completion = std::move(completion);
  entry.has_completion = true;
}

void SceneOverlays::SetArmPath(const std::string& scene_id, ArmPath path) {
  std::lock_guard lock(mutex_);
  Entry& entry = Touch(scene_id);
  entry.path = std::move(path);
  entry.has_path = true;
}

std::string SceneOverlays::Json(const std::string& scene_id) const {
  std::lock_guard lock(mutex_);
  const auto it = entries_.find(scene_id);
  if (it == entries_.end()) return "{\"version\":0,\"completion\":null,\"arm_path\":null}";
  const Entry& entry = it->second;
  std::string json = "{\"version\":" + std::to_string(entry.version) + ",\"completion\":";
  if (entry.has_completion) {
    const Completion& c = entry.completion;
    json += "{\"body_id\":" + JsonString(c.body_id) + ",\"point\":" + PointJson(c.point) + ",\"normal\":" +
            PointJson(c.normal) + ",\"score\":" + Number(c.score) + ",\"size\":" + Number(c.size) + "}";
  } else {
    json += "null";
  }
  json += ",\"arm_path\":";
  if (entry.has_path) {
    const ArmPath& p = entry.path;
    json += "{\"arm_id\":" + JsonString(p.arm_id) + ",\"tip_body\":" + JsonString(p.tip_body) + ",\"duration\":" +
            Number(p.duration) + ",\"direct\":" + (p.direct ? "true" : "false") + ",\"tip_points\":[";
    for (size_t i = 0; i < p.tip_points.size(); ++i) json += (i ? "," : "") + PointJson(p.tip_points[i]);
    json += "]}";
  } else {
    json += "null";
  }
  return json + "}";
}

}  // namespace graspsim::rpc
