#pragma once

#include <opencv2/core/mat.hpp>
#include <opencv2/core/types.hpp>

namespace everytouch::io {

// An image handed to ProjectorOutput::show (8-bit gray or BGR, one pixel per pixel of a panel of `panel`
// pixels) as BGR. Throws std::invalid_argument for any other size or type.
cv::Mat projectorImageInColour(const cv::Mat& image, cv::Size panel);

// Throws InputError naming [Projector] Delta= unless `delta` is 1..127 levels.
void checkCodeDelta(int delta);

}  // namespace everytouch::io
