#pragma once

#include <opencv2/core/mat.hpp>

namespace everytouch::test {

// A uniformly random binary code (CV_8UC1, 0/1), reproducible from its seed: any code will do where the
// rig's own (a second to generate) is not what is tested.
cv::Mat randomPattern(cv::Size size, unsigned seed);

}  // namespace everytouch::test
