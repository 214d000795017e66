#pragma once

#include <string>

#include <opencv2/core/mat.hpp>

namespace everytouch::test {

// What a colour camera's sensor records of `bgr` (CV_8UC3) behind the Bayer filter GenICam names `pattern`
// (BayerRG8, BayerBG8, BayerGR8, BayerGB8: the first row's first two filters): CV_8UC1, one channel a pixel.
cv::Mat bayerMosaic(const cv::Mat& bgr, const std::string& pattern);

}  // namespace everytouch::test
