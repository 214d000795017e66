#pragma once

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
AlternateGrabs grabAlternates(const VirtualDisplay& display, const cv::Mat& positive,
                              const cv::Mat& negative);

}  // namespace everytouch::test
