// What the browser viewer draws over a scene besides its bodies (rpc/http_viewer.h, GET overlays.json): the
// symmetry plane of the last shape completion added to the scene, with the body it added, and the tip path of
// the last arm path planned in it. Results of calls, not part of the scene: kept in memory only, the newest per
// scene, for a bounded number of scenes.
#pragma once

#include <array>
#include <cstdint>
#include <map>
#include <mutex>
#include <string>
#include <vector>

namespace graspsim::rpc {

class SceneOverlays {
 public:
  using Point = std::array<double, 3>;
  struct Completion {
    std::string body_id;  // the completed object in the scene
    Point point{}, normal{};  // the symmetry plane, world
    double score = 0;
    double size = 0;  // m: the completed mesh's bounding-box diagonal, for drawing the plane
  };
  struct ArmPath {
    std::string arm_id, tip_body;
    std::vector<Point> tip_points;  // world, along the path
    double duration = 0;            // s
    bool direct = false;
  };

  void SetCompletion(const std::string& scene_id, Completion completion);
  void SetArmPath(const std::string& scene_id, ArmPath path);
  // {"version": n, "completion": {...} | null, "arm_path": {...} | null}; version 0 when nothing was recorded.
  std::string Json(const std::string& scene_id) const;

 private:
  struct Entry {
    uint64_t version = 0;
    bool has_completion = false, has_path = false;
    Completion completion;
    ArmPath path;
  };
  Entry& Touch(const std::string& scene_id);  // under mutex_

  mutable std::mutex mutex_;
  std::map<std::string, Entry> entries_;
  uint64_t version_ = 0;
};

}  // namespace graspsim::rpc
