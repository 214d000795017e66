#pragma once

#include <opencv2/core/mat.hpp>

#include "eval/touch_scoring.h"

namespace everytouch::eval {

// The touch-down points over the display, as the paper's Fig. 15 and 17: each true contact point in green,
// the detected touch-down in red with a line to its trial's point, false touch-downs as red crosses, missed
// trials as green rings. CV_8UC3, display size.
cv::Mat plotTouchDowns(const TouchScore& score, cv::Size displaySize);

}  // namespace everytouch::eval
