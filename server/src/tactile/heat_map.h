// A tactile frame as a picture: a PNG heat map (OpenCV's colormap, private to heat_map.cpp, so nothing that
// includes this header compiles against OpenCV).
#pragma once

#include <string>

#include "tactile/tactile_frame.h"

namespace graspsim {

// `scale` pixels per texel; intensities from 0 (black) to max_intensity (the hottest colour).
std::string TactileImagePng(const TactileFrame& frame, unsigned max_intensity, unsigned scale);

}  // namespace graspsim
