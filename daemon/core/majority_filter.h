#pragma once

#include <opencv2/core/mat.hpp>

namespace everytouch::core {

// Buffers reused from call to call: once a mask of a size has been seen, nothing is allocated.
struct MajorityScratch {
    cv::Mat counts;  // CV_32SC1: integral image of the set pixels around the region, one row and column more
};

// Sets each pixel of `mask` (CV_8UC1, 0 / nonzero) inside `region` to 255 where more than half of the
// (2 radius + 1)^2 pixels around it are set and to 0 elsewhere: on a binary image the median filter of that
// window. It removes specks and notches narrower than about a radius and keeps outlines that run straight
// over a radius or more. Pixels outside the mask count as unset; pixels outside `region` are left alone.
void voteByMajority(cv::Mat& mask, cv::Rect region, int radius, MajorityScratch& scratch);

}  // namespace everytouch::core
