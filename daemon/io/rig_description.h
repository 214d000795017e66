#pragma once

#include <opencv2/core/mat.hpp>

#include "core/calibration.h"

namespace everytouch::io {

// What a rig that knows itself (the simulator, a recording) tells about the frames it delivers.
struct RigDescription {
    core::Calibration calibration;
    int delta = 10;          // code amplitude P, projector digital levels
    double frameRate = 120;  // camera frames per second
    cv::Mat pattern;         // CV_8UC1, projector size, 1 where the code bit is 1, 0 elsewhere
};

}  // namespace everytouch::io
