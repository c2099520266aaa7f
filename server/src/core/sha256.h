// SHA-256 of a byte string as lowercase hex: the checksum of uploads, and later the key of stored grasp sets.
#pragma once

#include <string>
#include <string_view>

namespace graspsim {

std::string Sha256Hex(std::string_view bytes);

}  // namespace graspsim
