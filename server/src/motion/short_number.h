// Private to motion/: numbers in diagnostics, 4 significant digits ("0.8512", "1.2e-05").
#pragma once

#include <cstdio>
#include <string>

namespace graspsim::motion {

inline std::string Short(double value) {
  char text[32];
  std::snprintf(text, sizeof text, "%.4g", value);
  return text;
}

}  // namespace graspsim::motion
