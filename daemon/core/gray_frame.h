#pragma once

#include <optional>
#include <string>

#include <opencv2/core/mat.hpp>

namespace everytouch::core {

// The gray view of an 8-bit gray or BGR camera frame, which the calibration detectors work on: `gray` shares
// the frame's pixels when it is gray already. Returns the problem when the frame is neither.
std::optional<std::string> grayFrame(const cv::Mat& cameraImage, cv::Mat& gray);

}  // namespace everytouch::core
