#pragma once

#include <opencv2/core/mat.hpp>

#include "core/calibration.h"

namespace everytouch::eval {

// The display as the camera sees it on the table: CV_8UC1 of the camera's size (raw pixels, through the lens
// distortion), 255 inside. Touches happen there; a hand's forearm outside it matters to no touch.
cv::Mat displayRegion(const core::Calibration& calibration);

}  // namespace everytouch::eval
