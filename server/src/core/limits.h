// Server-wide limits; each is a flag of graspsim-server. A request above a limit gets RESOURCE_EXHAUSTED.
#pragma once

#include <cstddef>
#include <cstdint>

namespace graspsim {

struct Limits {
  size_t max_scenes = 256;
  size_t max_bodies_per_scene = 1024;
  size_t max_triangles_per_mesh = 2'000'000;
  uint64_t max_upload_bytes = 256ull << 20;       // one uploaded file
  uint64_t max_scene_file_bytes = 1024ull << 20;  // all files of one scene
  size_t max_cloud_points = 2'000'000;            // points of a cloud, or pixels of a depth image (perception)
};

}  // namespace graspsim
