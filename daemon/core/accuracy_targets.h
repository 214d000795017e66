#pragma once

#include <opencv2/core/mat.hpp>
#include <opencv2/core/types.hpp>

namespace everytouch::core {

// The accuracy test's display (core/accuracy_grid.h): its 35 circles, each with a cross on its centre, dark
// on a light ground, `displaySize` pixels, BGR. The simulated projector shows it in the grid35 scenario, and
// a camera rig's projector while everytouch-calib test runs.
cv::Mat drawAccuracyTargets(cv::Size displaySize);

}  // namespace everytouch::core
