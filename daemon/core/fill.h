#pragma once

#include <cstring>

#include <opencv2/core/mat.hpp>

namespace everytouch::core {

// Sets every byte of an 8-bit single-channel image (or a region of one) to `value`. cv::Mat::setTo allocates
// a buffer on every call, which the per-frame path must not.
inline void fill(cv::Mat image, uchar value) {
    CV_Assert(image.type() == CV_8UC1);
    for (int y = 0; y < image.rows; ++y)
        std::memset(image.ptr<uchar>(y), value, static_cast<std::size_t>(image.cols));
}

}  // namespace everytouch::core
