// Tactile frames as PNG heat maps with OpenCV, which stays private to this file (see heat_map.h).
#include "tactile/heat_map.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "core/error.h"

namespace graspsim {

std::string TactileImagePng(const TactileFrame& frame, unsigned max_intensity, unsigned scale) {
  if (frame.rows == 0 || frame.cols == 0 || frame.intensities.size() != size_t{frame.rows} * frame.cols) {
    throw Error(ErrorCode::kInternal, "tactile image: frame of " + std::to_string(frame.intensities.size()) +
                                          " intensities is not " + std::to_string(frame.rows) + " x " +
                                          std::to_string(frame.cols));
  }
  // Image row = texel row (pad y, top to bottom), image column = texel column (pad x).
  cv::Mat gray(static_cast<int>(frame.rows), static_cast<int>(frame.cols), CV_8UC1);
  for (unsigned r = 0; r < frame.rows; ++r) {
    for (unsigned c = 0; c < frame.cols; ++c) {
      const double value = frame.intensities[size_t{r} * frame.cols + c];
      const double level = max_intensity == 0 ? 0 : std::min(1.0, value / max_intensity);
      gray.at<uint8_t>(static_cast<int>(r), static_cast<int>(c)) = static_cast<uint8_t>(std::lround(255 * level));
    }
  }
  // Inferno: perceptually uniform and monotonic in lightness (it reads right in grey print too), and black at
  // zero, so an untouched pad is a black image and the hottest texel is the brightest.
  cv::Mat heat;
  cv::applyColorMap(gray, heat, cv::COLORMAP_INFERNO);
  const int s = static_cast<int>(std::max(1u, scale));
  cv::Mat image;
  cv::resize(heat, image, cv::Size(gray.cols * s, gray.rows * s), 0, 0, cv::INTER_NEAREST);
  std::vector<uint8_t> png;
  if (!cv::imencode(".png", image, png)) throw Error(ErrorCode::kInternal, "tactile image: PNG encoding failed");
  return std::string(png.begin(), png.end());
}

}  // namespace graspsim
