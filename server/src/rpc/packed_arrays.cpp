#include "rpc/packed_arrays.h"

#include "core/error.h"

namespace graspsim::rpc {

size_t PackedCount(const std::string& field, size_t bytes, size_t element_size, std::string_view unit) {
  if (bytes % element_size != 0) {
    ThrowInvalidArgument(field + ": " + std::to_string(bytes) + " bytes is not a multiple of " +
                         std::to_string(element_size) + " (" + std::string(unit) + ")");
  }
  return bytes / element_size;
}

}  // namespace graspsim::rpc
