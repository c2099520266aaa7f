// Reads the messages of an MCAP file front to back (chunks decompressed in turn), the way a stream reader does:
// no index needed, so a file whose writer was killed reads up to its last whole chunk. Enough for a server to
// replay its own recordings; readers of other tools' files are the PyPI and npm `mcap` packages.
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <string_view>

namespace graspsim::recording {

struct McapMessage {
  std::string_view topic, schema_name;
  uint64_t log_time = 0;
  std::string_view data;
};

// Calls `on_message` for every message in file order. Throws Error(kFailedPrecondition) naming `label` (the
// name a caller knows the file by) when it is not an MCAP file or a record is corrupt, Error(kNotFound) when it
// cannot be opened; a file cut short ends the scan without an error.
void ReadMcap(const std::string& path, const std::string& label,
              const std::function<void(const McapMessage&)>& on_message);

}  // namespace graspsim::recording
