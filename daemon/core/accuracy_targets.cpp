#include "core/accuracy_targets.h"

#include <algorithm>
#include <cmath>

#include <opencv2/imgproc.hpp>

#include "core/accuracy_grid.h"

namespace everytouch::core {

cv::Mat drawAccuracyTargets(cv::Size displaySize) {
    cv::Mat image(displaySize, CV_8UC3, cv::Scalar(245, 245, 245));
    const double scale = displaySize.width / 640.0;
    const int radius =
        static_cast<int>(std::lround(accuracyGridCircleRadius(displaySize.width, displaySize.height)));
    for (const DisplayPoint& centre : accuracyGridCentres(displaySize.width, displaySize.height)) {
        const cv::Point c(static_cast<int>(std::lround(centre.x)), static_cast<int>(std::lround(centre.y)));
        cv::circle(image, c, radius, cv::Scalar(60, 60, 60), std::max(1, static_cast<int>(2 * scale)),
                   cv::LINE_AA);
        cv::drawMarker(image, c, cv::Scalar(40, 40, 200), cv::MARKER_CROSS, radius, 1, cv::LINE_AA);
    }
    return image;
}

}  // namespace everytouch::core
