// Where the source tree is, for tests that read files kept in it (fuzz regressions, the proto files) or fetched
// into its build folder (bench data).
#pragma once

#include <string>

namespace graspsim {

// The source tree's absolute path, without a trailing slash.
std::string SourceTree();

}  // namespace graspsim
