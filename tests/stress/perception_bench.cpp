// graspsim_perception_bench: the in-process figures of `tests/bench/run shape` as one JSON object (stdout;
// progress on stderr). Wall times are reported, never judged.
//
// Reconstruction only (issue 5, stage 5): oriented points with exact normals → closed mesh, ours
// (perception/poisson.h) against PCL's pcl::Poisson (Kazhdan's octree code, one thread, its defaults but the
// depth) on the same points in the same run. Clouds: a 10 cm sphere (Fibonacci spiral) and a 10 × 7 × 5 cm box
// (face grids), each at ~2.1k and ~39k points — the sizes of the paper's timing (PAPERS.md part C). Depths 5 and 7.
// Per run: the median wall time of `repeats` runs, the mean two-sided deviation from the analytic surface (mm;
// 20k uniform samples of the mesh against the exact distance, and the cloud against the mesh), triangles, and
// our per-stage times. Plus the plane-fit normals' time (k = 10) on the same clouds, the stage before this one.
// Symmetry search, segmentation and the service are not built yet: these are not the end-to-end figures.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <functional>
#include <iostream>
#include <string>
#include <vector>

#include <pcl/PolygonMesh.h>
#include <pcl/conversions.h>
#include <pcl/point_types.h>
#include <pcl/surface/poisson.h>

#include "cpp/perception/shapes.h"
#include "perception/mesh_metrics.h"
#include "perception/normals.h"
#include "perception/poisson.h"

namespace graspsim {
namespace {

using Clock = std::chrono::steady_clock;
double MsSince(Clock::time_point start) { return std::chrono::duration<double, std::milli>(Clock::now() - start).count(); }

double Median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

struct Shape {
  std::string name;
  test_shapes::OrientedCloud cloud;
  std::function<double(const Vec3&)> distance;
};

double MeanDeviationMm(const TriangleMesh& mesh, const Shape& shape) {
  if (mesh.triangles.empty()) return NAN;
  double there = 0, back = 0;
  const std::vector<Vec3> samples = SampleSurface(mesh, 20000, 7);
  for (const Vec3& p : samples) there += std::abs(shape.distance(p));
  const MeshDistance to_mesh(mesh);
  for (const Vec3& p : shape.cloud.points) back += to_mesh.Distance(p);
  return 1e3 * (there / double(samples.size()) + back / double(shape.cloud.points.size())) / 2;
}

TriangleMesh PclPoisson(const Shape& shape, int depth) {
  pcl::PointCloud<pcl::PointNormal>::Ptr cloud(new pcl::PointCloud<pcl::PointNormal>);
  for (size_t i = 0; i < shape.cloud.points.size(); ++i) {
    pcl::PointNormal p;
    p.x = float(shape.cloud.points[i].x());
    p.y = float(shape.cloud.points[i].y());
    p.z = float(shape.cloud.points[i].z());
    p.normal_x = float(shape.cloud.normals[i].x());
    p.normal_y = float(shape.cloud.normals[i].y());
    p.normal_z = float(shape.cloud.normals[i].z());
    cloud->push_back(p);
  }
  pcl::Poisson<pcl::PointNormal> poisson;
  poisson.setDepth(depth);
  poisson.setThreads(1);
  poisson.setInputCloud(cloud);
  pcl::PolygonMesh polygons;
  poisson.reconstruct(polygons);
  pcl::PointCloud<pcl::PointXYZ> vertices;
  pcl::fromPCLPointCloud2(polygons.cloud, vertices);
  TriangleMesh mesh;
  for (const auto& v : vertices) mesh.vertices.emplace_back(v.x, v.y, v.z);
  for (const auto& polygon : polygons.polygons) {
    for (size_t i = 1; i + 1 < polygon.vertices.size(); ++i) {  // fan any polygon (PCL's are triangles by default)
      mesh.triangles.push_back({uint32_t(polygon.vertices[0]), uint32_t(polygon.vertices[i]), uint32_t(polygon.vertices[i + 1])});
    }
  }
  return mesh;
}

std::string Num(double x) {
  if (!std::isfinite(x)) return "null";
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%.4g", x);
  return buffer;
}

}  // namespace
}  // namespace graspsim

int main(int argc, char** argv) {
  using namespace graspsim;
  const int repeats = argc > 1 ? std::max(1, std::atoi(argv[1])) : 5;
  const double r = 0.05;
  const Vec3 box(0.10, 0.07, 0.05);
  const double box_area = 2 * (box.x() * box.y() + box.y() * box.z() + box.z() * box.x());
  std::vector<Shape> shapes;
  for (int n : {2100, 39416}) {
    shapes.push_back({"sphere", test_shapes::Sphere(r, n), [r](const Vec3& p) { return test_shapes::SphereDistance(p, r); }});
    shapes.push_back({"box", test_shapes::Box(box, std::sqrt(box_area / n)),
                      [box](const Vec3& p) { return test_shapes::BoxDistance(p, box); }});
  }
  std::string rows;
  for (const Shape& shape : shapes) {
    NormalEstimationParams normal_params;
    std::vector<double> normal_ms;
    for (int i = 0; i < repeats; ++i) {
      const auto start = Clock::now();
      EstimateNormals(shape.cloud.points, normal_params);
      normal_ms.push_back(MsSince(start));
    }
    for (int depth : {5, 7}) {
      std::cerr << shape.name << " " << shape.cloud.points.size() << " points, depth " << depth << "\n";
      PoissonParams params;
      params.depth = depth;
      std::vector<double> ours_ms, stage[4];
      PoissonResult ours;
      for (int i = 0; i < repeats; ++i) {
        const auto start = Clock::now();
        ours = ReconstructSurface(shape.cloud.points, shape.cloud.normals, params);
        ours_ms.push_back(MsSince(start));
        stage[0].push_back(ours.stats.ms_grid_splat);
        stage[1].push_back(ours.stats.ms_solve);
        stage[2].push_back(ours.stats.ms_iso);
        stage[3].push_back(ours.stats.ms_extract);
      }
      std::vector<double> pcl_ms;
      TriangleMesh reference;
      for (int i = 0; i < std::max(1, repeats / 2); ++i) {
        const auto start = Clock::now();
        reference = PclPoisson(shape, depth);
        pcl_ms.push_back(MsSince(start));
      }
      const EdgeCounts edges = CountEdges(ours.mesh), pcl_edges = CountEdges(reference);
      if (!rows.empty()) rows += ",\n  ";
      rows += "{\"shape\": \"" + shape.name + "\", \"points\": " + std::to_string(shape.cloud.points.size()) +
              ", \"depth\": " + std::to_string(depth) + ", \"ms\": " + Num(Median(ours_ms)) +
              ", \"ms_per_stage\": {\"grid_splat\": " + Num(Median(stage[0])) + ", \"solve\": " + Num(Median(stage[1])) +
              ", \"iso\": " + Num(Median(stage[2])) + ", \"extract\": " + Num(Median(stage[3])) +
              "}, \"solver_iterations\": " + std::to_string(ours.stats.solver_iterations) +
              ", \"solved_depth\": " + std::to_string(ours.stats.solved_depth) +
              ", \"mean_dev_mm\": " + Num(MeanDeviationMm(ours.mesh, shape)) +
              ", \"triangles\": " + std::to_string(ours.mesh.triangles.size()) +
              ", \"closed\": " + (edges.Closed() ? "true" : "false") +
              ", \"pcl_ms\": " + Num(Median(pcl_ms)) + ", \"pcl_mean_dev_mm\": " + Num(MeanDeviationMm(reference, shape)) +
              ", \"pcl_triangles\": " + std::to_string(reference.triangles.size()) +
              ", \"pcl_closed\": " + (pcl_edges.Closed() ? "true" : "false") +
              ", \"normals_ms\": " + Num(Median(normal_ms)) + "}";
    }
  }
  std::cout << "{\"repeats\": " << repeats << ", \"runs\": [\n  " << rows << "\n]}\n";
  return 0;
}
