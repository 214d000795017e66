#pragma once

#include <opencv2/core/mat.hpp>

#include "core/calibration.h"

namespace everytouch::core {

// The code the camera sees where the projector's light falls on the bare table: the pattern carried into the
// camera through the table's homography and blurred as the camera integrates it, in units of one projector
// bit (1 where a 1-bit's light lands fully, 0 where a 0-bit's does). Where the table is in view, S is this
// image scaled by the local amplitude 2 delta * gain * albedo plus noise; anywhere else (a hand above the
// table, a shadow, content that changed between the two frames) S does not follow it. Computed once per
// calibration.
struct TableCode {
    cv::Mat predicted;  // CV_32FC1, camera size; negative where no projector pixel lands
    // The camera pixel's footprint on the panel: how many projector pixels wide one camera pixel is at the
    // image centre. Above one the camera cannot resolve single code bits (docs/structured-light.md).
    double projectorPixelsPerCameraPixel = 1.0;
};

// pattern: CV_8UC1, projector size, 0/1. The blur follows from the geometry: a camera pixel integrates the
// panel over its footprint (a box projectorPixelsPerCameraPixel wide, approximated by a Gaussian of the same
// variance), and the camera's own optics add cameraBlurPx (Gaussian sigma, camera pixels).
TableCode predictTableCode(const Calibration& calibration, const cv::Mat& pattern, double cameraBlurPx = 0.5);

}  // namespace everytouch::core
