// Numbers in messages: the shortest text that reads back as the same double ("0.1", "-2", "nan", "inf"), so an
// error shows exactly the value the client sent.
#pragma once

#include <string>

namespace graspsim {

std::string FormatNumber(double value);

}  // namespace graspsim
