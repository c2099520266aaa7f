// The source tree's path is compiled into this file alone. As a definition on every test file it would put an
// absolute path on each of their command lines, and ccache (hashing command lines relative to the source tree)
// could not reuse them in another clone.
#include "source_tree.h"

namespace graspsim {

std::string SourceTree() { return GRASPSIM_SOURCE_DIR; }

}  // namespace graspsim
