#pragma once

#include <opencv2/core/mat.hpp>

#include "core/result.h"

namespace everytouch::core {

// The gray view of an 8-bit gray or BGR camera frame, which the calibration detectors work on: `gray` shares
// the frame's pixels when it is gray already, and is reallocated only when the size changes otherwise. Fails
// when the frame is neither.
Status grayFrame(const cv::Mat& cameraImage, cv::Mat& gray);

}  // namespace everytouch::core
