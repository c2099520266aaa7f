// graspsim_grasp_bench: the in-process figures of `tests/bench/run grasp` as one JSON object (stdout; progress on
// stderr). Wall and CPU times are reported, never judged.
//
//   graspsim_grasp_bench [--threads N] [--repeat R] [--hand NAME]... [--max-grasps N] FILE.stl...
//
// Each binary STL is welded (exact float32 corners, sorted as numpy.unique(axis=0) sorts them, so the mesh is
// the one tests/bench/grasp.py sends) and planned with every built-in hand as the benchmark plans it:
// bounding-box candidates at δ = 1 cm, every pre-shape, 4 rolls, standoff 0, seed 1, no obstacles. Per hand:
// candidates, the planner's wall time (GraspSet.seconds) and its threads' CPU time (GraspSet.cpu_seconds: on a
// loaded machine the fairer figure, candidates per CPU second = per core), and a fingerprint of
// the answers (outcome counts, the sum of every kept ε) so that a speed change can be checked to change nothing.
#include <array>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <iostream>
#include <map>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "grasp/planner.h"

namespace {

using graspsim::TriangleMesh;
namespace g = graspsim::grasp;

std::shared_ptr<TriangleMesh> ReadStl(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::string data((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (data.size() < 84) throw std::runtime_error(path + ": not a binary STL");
  uint32_t count = 0;
  std::memcpy(&count, data.data() + 80, 4);
  if (data.size() < 84 + 50ull * count) throw std::runtime_error(path + ": truncated");
  std::vector<std::array<float, 3>> corners(3ull * count);
  for (uint32_t i = 0; i < count; ++i) std::memcpy(corners[3ull * i].data(), data.data() + 84 + 50ull * i + 12, 36);
  std::map<std::array<float, 3>, uint32_t> index;
  for (const auto& c : corners) index.emplace(c, 0);
  auto mesh = std::make_shared<TriangleMesh>();
  for (auto& [c, i] : index) {
    i = static_cast<uint32_t>(mesh->vertices.size());
    mesh->vertices.emplace_back(c[0], c[1], c[2]);
  }
  for (uint32_t t = 0; t < count; ++t) {
    mesh->triangles.push_back({index[corners[3ull * t]], index[corners[3ull * t + 1]], index[corners[3ull * t + 2]]});
  }
  return mesh;
}

std::string Base(const std::string& path) {
  std::string name = path.substr(path.find_last_of('/') + 1);
  return name.substr(0, name.find_last_of('.'));
}

}  // namespace

int main(int argc, char** argv) {
  int threads = 1, repeat = 1;
  size_t max_grasps = 0;  // all: the fingerprint covers every force-closure grasp (64 qhull volumes, not timed)
  std::vector<std::string> files, hands;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg == "--threads" && i + 1 < argc) {
      threads = std::stoi(argv[++i]);
    } else if (arg == "--max-grasps" && i + 1 < argc) {
      max_grasps = std::stoul(argv[++i]);
    } else if (arg == "--hand" && i + 1 < argc) {
      hands.push_back(argv[++i]);
    } else if (arg == "--repeat" && i + 1 < argc) {
      repeat = std::stoi(argv[++i]);
    } else {
      files.push_back(arg);
    }
  }
  if (files.empty()) {
    std::cerr << "usage: graspsim_grasp_bench [--threads N] [--repeat R] [--hand NAME]... [--max-grasps N] FILE.stl...\n";
    return 2;
  }
  std::vector<std::pair<std::string, std::shared_ptr<TriangleMesh>>> meshes;
  for (const auto& f : files) meshes.emplace_back(Base(f), ReadStl(f));

  std::ostringstream json;
  json.precision(10);
  json << "{\"threads\": " << threads << ", \"repeat\": " << repeat;
  if (hands.empty()) hands = g::HandNames();
  for (const std::string& hand : hands) {
    uint64_t candidates = 0, missed = 0, collisions = 0, simulated = 0, fc = 0;
    double wall = 0, cpu = 0, epsilon_sum = 0;
    for (const auto& [name, mesh] : meshes) {
      g::GraspPlanner planner(hand, mesh, {}, g::ClosingParams());
      g::CandidateParams params;
      params.spacing = 0.01;
      params.rolls = 4;
      params.preshapes.clear();
      for (uint32_t p = 0; p < planner.hand().preshape_names().size(); ++p) params.preshapes.push_back(p);
      const std::vector<g::Candidate> list = planner.Candidates(params);
      for (int r = 0; r < repeat; ++r) {
        const auto set = planner.Plan(list, threads, max_grasps, [](size_t, size_t) { return true; });
        cpu += set->cpu_seconds;
        wall += set->seconds;
        candidates += set->candidates;
        if (r == 0) {
          missed += set->missed;
          collisions += set->collisions;
          simulated += set->simulated;
          fc += set->force_closure;
          for (const auto& grasp : set->grasps) epsilon_sum += grasp.quality.epsilon;
          std::fprintf(stderr, "%s %s: %zu candidates, %.3f s, %lu force closure, eps sum %.12g\n", hand.c_str(),
                       name.c_str(), list.size(), set->seconds, static_cast<unsigned long>(set->force_closure),
                       [&] { double s = 0; for (const auto& x : set->grasps) s += x.quality.epsilon; return s; }());
        }
      }
    }
    json << ", \"" << hand << "\": {\"candidates\": " << candidates << ", \"wall_s\": " << wall
         << ", \"cpu_s\": " << cpu << ", \"per_wall_s\": " << candidates / wall << ", \"per_cpu_s\": "
         << candidates / cpu << ", \"missed\": " << missed << ", \"collisions\": " << collisions
         << ", \"simulated\": " << simulated << ", \"force_closure\": " << fc << ", \"epsilon_sum\": " << epsilon_sum
         << "}";
  }
  json << "}";
  std::cout << json.str() << std::endl;
  return 0;
}
