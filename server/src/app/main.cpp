// graspsim-server: parse flags, start the gRPC server, wait for SIGTERM/SIGINT, drain, exit 0.
#include <csignal>
#include <cstdio>
#include <cstdlib>

#include <malloc.h>
#include <pthread.h>

#include <absl/synchronization/mutex.h>

#include "app/flags.h"
#include "core/compute_pool.h"
#include "core/error.h"
#include "core/log.h"

int main(int argc, char** argv) {
  graspsim::ServerFlags flags;
  try {
    flags = graspsim::ParseFlags(argc, argv);
  } catch (const graspsim::Error& error) {
    std::fprintf(stderr, "graspsim-server: %s\n", error.what());
    return 2;
  }
  if (flags.help) {
    std::fputs(graspsim::FlagsHelp().c_str(), stdout);
    return 0;
  }
  graspsim::SetLogLevel(flags.log_level);
  // Debian's Abseil is built without NDEBUG, so every absl::Mutex inside gRPC records lock order in a global graph
  // (GraphCycles) to detect deadlocks: about a sixth of a cheap call's server CPU (tests/bench/run rpc). Our own
  // locks are std::mutex; gRPC's own tests, not this server, are the place to find gRPC's lock-order bugs.
  absl::SetMutexDeadlockDetectionMode(absl::OnDeadlockCycle::kIgnore);
  // Keep freed memory for the next request instead of handing it back to the kernel: a 39k-point shape completion
  // allocates ~30 MB of buffers, and pages fresh from the kernel (faulted in and zeroed each time) cost ~12 % of its
  // time (docs/benchmarks.md, shape). glibc's own adaptive threshold stops at 32 MB, and thread arenas trim anyway.
  mallopt(M_MMAP_THRESHOLD, 256 << 20);
  mallopt(M_TRIM_THRESHOLD, 512 << 20);

  // Block the stop signals before gRPC starts its threads, so that only sigwait below receives them.
  sigset_t stop_signals;
  sigemptyset(&stop_signals);
  sigaddset(&stop_signals, SIGTERM);
  sigaddset(&stop_signals, SIGINT);
  pthread_sigmask(SIG_BLOCK, &stop_signals, nullptr);
  std::signal(SIGPIPE, SIG_IGN);
  // Started here, after the mask, so that its threads leave the stop signals to sigwait as well.
  graspsim::ComputePool::Configure(flags.compute_threads);
  graspsim::Log(graspsim::LogLevel::kInfo, "compute pool",
                {{"threads", std::to_string(graspsim::ComputePool::Shared().threads())}});

  try {
    graspsim::rpc::GraspsimServer server(flags.server);
    int signal_number = 0;
    sigwait(&stop_signals, &signal_number);
    graspsim::Log(graspsim::LogLevel::kInfo, "stop signal", {{"signal", std::to_string(signal_number)}});
    server.Shutdown();
  } catch (const graspsim::Error& error) {
    graspsim::Log(graspsim::LogLevel::kError, "cannot start", {{"error", error.what()}});
    return 1;
  }
  return 0;
}
