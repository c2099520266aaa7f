// graspsim-server's flags. Every flag can also be set in a config file (--config=FILE: "name = value" lines,
// '#' comments); the command line wins over the file.
#pragma once

#include <string>

#include "core/log.h"
#include "rpc/server.h"

namespace graspsim {

struct ServerFlags {
  rpc::ServerOptions server;
  LogLevel log_level = LogLevel::kInfo;
  size_t compute_threads = 0;  // the shared ComputePool; 0 = DefaultComputeThreads()
  bool help = false;
};

// Throws Error(kInvalidArgument) naming the flag and the value.
ServerFlags ParseFlags(int argc, char** argv);
std::string FlagsHelp();

}  // namespace graspsim
