// Throughput figures for the contact finder, not tests (tests never assert a wall-clock time). Disabled by
// default; run with
//   graspsim_tests --gtest_also_run_disabled_tests --gtest_filter='ContactBench*'
#include <chrono>
#include <cstdio>
#include <random>

#include <gtest/gtest.h>

#include "collision/contact_finder.h"
#include "collision/mesh_query.h"
#include "collision_fixtures.h"

namespace graspsim {
namespace {

using namespace collision_fixtures;
using Clock = std::chrono::steady_clock;

double Seconds(Clock::time_point since) { return std::chrono::duration<double>(Clock::now() - since).count(); }

// Calls `fn` in rounds until at least `budget` seconds passed; returns seconds per call.
template <typename Fn>
double TimePerCall(Fn&& fn, double budget = 1.0) {
  fn();  // warm caches
  long calls = 0;
  const auto start = Clock::now();
  do {
    for (int i = 0; i < 100; ++i) fn();
    calls += 100;
  } while (Seconds(start) < budget);
  return Seconds(start) / calls;
}

TEST(ContactBench, DISABLED_CubeOnTable) {
  const SceneModel model = Model({Body("table", BoxGeometry(Vec3(1, 1, 0.05)), BodyMotion::kStatic),
                                  Body("cube", BoxGeometry(Vec3(0.05, 0.05, 0.05)))});
  const ContactFinder finder(model);
  const std::vector<Pose> poses{At(0, 0, -0.025), At(0.00125, 0.00125, 0.024)};
  std::vector<ContactPoint> contacts;
  const double t = TimePerCall([&] {
    contacts.clear();
    finder.Find(poses, &contacts);
  });
  std::printf("{\"case\": \"cube_on_table\", \"table_samples\": %zu, \"contacts\": %zu, \"find_us\": %.2f, "
              "\"finds_per_s\": %.0f, \"contacts_per_s\": %.3g}\n",
              finder.Samples(0).size(), contacts.size(), t * 1e6, 1 / t, contacts.size() / t);
}

TEST(ContactBench, DISABLED_PrimitivePointTests) {
  // Every sample of a dense sphere (1 mm spacing) lies inside a large box: one exact box test per sample.
  const SceneModel model = Model({Body("block", BoxGeometry(Vec3(1, 1, 1)), BodyMotion::kStatic),
                                  Body("ball", SphereGeometry(0.05))});
  const ContactFinder finder(model, {0.001, 0});
  const std::vector<Pose> poses{At(0, 0, 0), At(0.1, 0.1, 0.1)};
  std::vector<ContactPoint> contacts;
  contacts.reserve(finder.Samples(1).size());
  const double t = TimePerCall([&] {
    contacts.clear();
    finder.Find(poses, &contacts);
  });
  std::printf("{\"case\": \"primitive_point_tests\", \"samples\": %zu, \"contacts\": %zu, \"find_ms\": %.3f, "
              "\"point_tests_per_s\": %.3g}\n",
              finder.Samples(1).size(), contacts.size(), t * 1e3, finder.Samples(1).size() / t);
}

TEST(ContactBench, DISABLED_MeshPointTests) {
  // A 10 000-triangle closed sphere mesh; query points uniform in its bounding box (about half inside).
  const double r = 0.05;
  const auto mesh = SphereMesh(r, 100, 51);
  const auto build_start = Clock::now();
  const collision::MeshBvh bvh(mesh);
  const double build = Seconds(build_start);
  // Two point sets: uniform in the bounding box (deep points are the slow case: every facet is about equally
  // far) and within 5 mm of the surface (where contact samples are: penetrations are shallow).
  std::mt19937 rng(1);
  std::uniform_real_distribution<double> coordinate(-r, r), shell(r - 0.005, r + 0.005);
  std::normal_distribution<double> gauss;
  std::vector<Vec3> uniform(100000), near_surface(100000);
  for (Vec3& p : uniform) p = Vec3(coordinate(rng), coordinate(rng), coordinate(rng));
  for (Vec3& p : near_surface) p = shell(rng) * Vec3(gauss(rng), gauss(rng), gauss(rng)).normalized();
  for (const auto& [name, points] : {std::pair{"uniform_in_box", &uniform}, std::pair{"within_5mm", &near_surface}}) {
    for (double margin : {0.0, 0.005}) {
      size_t hits = 0;
      const auto start = Clock::now();
      double depth;
      Vec3 normal;
      for (const Vec3& p : *points) hits += bvh.Depth(p, margin, &depth, &normal);
      const double t = Seconds(start);
      std::printf("{\"case\": \"mesh_point_tests\", \"points\": \"%s\", \"triangles\": %zu, "
                  "\"bvh_build_ms\": %.2f, \"margin_m\": %g, \"reported\": %zu, \"point_tests_per_s\": %.3g}\n",
                  name, mesh->TriangleCount(), build * 1e3, margin, hits, points->size() / t);
    }
  }
}

TEST(ContactBench, DISABLED_MeshOnTable) {
  // The same mesh as a free body 2 mm into the table: table samples under it go through Embree.
  const SceneModel model = Model({Body("table", BoxGeometry(Vec3(1, 1, 0.05)), BodyMotion::kStatic),
                                  Body("ball", MeshGeometry(SphereMesh(0.05, 100, 51)))});
  const ContactFinder finder(model);
  const std::vector<Pose> poses{At(0, 0, -0.025), At(0, 0, 0.048)};
  std::vector<ContactPoint> contacts;
  const double t = TimePerCall([&] {
    contacts.clear();
    finder.Find(poses, &contacts);
  });
  std::printf("{\"case\": \"mesh_on_table\", \"contacts\": %zu, \"find_us\": %.2f}\n", contacts.size(), t * 1e6);
}

}  // namespace
}  // namespace graspsim
