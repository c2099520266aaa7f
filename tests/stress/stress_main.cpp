// graspsim_stress [--reduced] [--jobs N]: runs the stability sweep (stress/sweep.h) and prints one JSON line per
// run (in completion order) and a last summary line {"summary": …}. Progress goes to stderr.
// graspsim_stress --point SCENARIO INTEGRATOR DT MASS K C SIGMA0 SIGMA1: one run, traced step by step on stderr
// (to look at a point of the tables), e.g. --point slide linearly_implicit_euler 1e-3 0.05 1e4 10 1e4 30.
#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <iostream>
#include <mutex>
#include <thread>

#include "stress/sweep.h"

int main(int argc, char** argv) {
  using namespace graspsim::stress;
  bool reduced = false;
  unsigned jobs = std::max(1u, std::thread::hardware_concurrency());
  for (int i = 1; i < argc; ++i) {
    if (std::strcmp(argv[i], "--reduced") == 0) {
      reduced = true;
    } else if (std::strcmp(argv[i], "--point") == 0 && i + 8 < argc) {
      RunSpec spec;
      spec.trace = true;
      for (Scenario s : {Scenario::kTipOnTable, Scenario::kTipOnObject, Scenario::kSlide}) {
        if (Name(s) == std::string(argv[i + 1])) spec.scenario = s;
      }
      for (auto g : {graspsim::Integrator::kSemiImplicitEuler, graspsim::Integrator::kLinearlyImplicitEuler,
                     graspsim::Integrator::kVelocityVerlet}) {
        if (Name(g) == std::string(argv[i + 2])) spec.integrator = g;
      }
      spec.time_step = std::atof(argv[i + 3]);
      spec.mass = std::atof(argv[i + 4]);
      spec.contact.stiffness = std::atof(argv[i + 5]);
      spec.contact.damping = std::atof(argv[i + 6]);
      spec.contact.bristle_stiffness = std::atof(argv[i + 7]);
      spec.contact.bristle_damping = std::atof(argv[i + 8]);
      if (spec.scenario == Scenario::kSlide) spec.min_duration = kSlideMinDuration;
      std::cout << ToJson(spec, RunOne(spec)) << std::endl;
      return 0;
    } else if (std::strcmp(argv[i], "--jobs") == 0 && i + 1 < argc) {
      jobs = std::max(1, std::atoi(argv[++i]));
    } else {
      std::fprintf(stderr, "usage: %s [--reduced] [--jobs N]\n", argv[0]);
      return 2;
    }
  }
  const std::vector<RunSpec> specs = reduced ? ReducedSweep() : FullSweep();
  const auto started = std::chrono::steady_clock::now();
  std::atomic<size_t> next{0};
  std::mutex mutex;
  size_t done = 0, stable = 0, diverged = 0, insane = 0, breaches = 0;
  auto worker = [&] {
    for (size_t i; (i = next++) < specs.size();) {
      const RunResult result = RunOne(specs[i]);
      std::lock_guard<std::mutex> lock(mutex);
      std::cout << ToJson(specs[i], result) << "\n";
      ++done;
      stable += result.stable;
      diverged += result.reason == "diverged";
      insane += !result.stable && result.reason != "diverged";
      breaches += !result.contract.empty();
      if (done % 100 == 0) std::cerr << "graspsim_stress: " << done << "/" << specs.size() << " runs\n";
    }
  };
  std::vector<std::thread> threads;
  for (unsigned j = 0; j < jobs; ++j) threads.emplace_back(worker);
  for (std::thread& t : threads) t.join();
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  std::cout << "{\"summary\":true,\"sweep\":\"" << (reduced ? "reduced" : "full") << "\",\"runs\":" << specs.size()
            << ",\"stable\":" << stable << ",\"diverged\":" << diverged << ",\"insane\":" << insane
            << ",\"contract_breaches\":" << breaches << ",\"stable_fraction\":"
            << static_cast<double>(stable) / specs.size() << ",\"jobs\":" << jobs << ",\"seconds\":" << seconds
            << "}" << std::endl;
  return breaches == 0 ? 0 : 1;
}
