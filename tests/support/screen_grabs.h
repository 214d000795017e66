#pragma once

#include <functional>

#include <opencv2/core/mat.hpp>

#include "support/virtual_display.h"

namespace everytouch::test {

// Whether two images are the same within one level (a compositor's or a scaler's rounding).
bool sameImage(const cv::Mat& a, const cv::Mat& b);

// The screen as it shows `positive` and as it shows `negative`, each grabbed from the screen within 10 s;
// empty when it showed neither in that time.
struct AlternateGrabs {
    cv::Mat positive, negative;
    int others = 0;  // grabs after the first match that were neither
};
AlternateGrabs grabAlternates(const std::function<cv::Mat()>& grab, const cv::Mat& positive,
                              const cv::Mat& negative);
AlternateGrabs grabAlternates(const VirtualDisplay& display, const cv::Mat& positive,
                              const cv::Mat& negative);

// A screen of one colour with the code over it, grabbed within 10 s once as it shows the "+" image (one
// colour on the pattern's 1-bits, another on its 0-bits, brighter by `delta` or more in the sum of the
// channels) and once as it shows the "-" image; empty when it showed neither in that time. Grabs of anything
// else (a calibration image still up, two frames mixed) are counted as others. For a compositor whose
// blending under the overlay is not known to the level (sway's pixman renderer lays a uniform copy of one of
// the overlay's pixels under it), where the images it shows cannot be predicted but their difference can.
AlternateGrabs grabBothPolarities(const std::function<cv::Mat()>& grab, const cv::Mat& pattern, int delta);

}  // namespace everytouch::test
