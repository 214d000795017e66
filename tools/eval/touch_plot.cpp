#include "eval/touch_plot.h"

#include <opencv2/imgproc.hpp>

namespace everytouch::eval {

namespace {

const cv::Scalar kBackground(40, 40, 40);
const cv::Scalar kTruth(0, 200, 0);
const cv::Scalar kDetected(0, 0, 255);
const cv::Scalar kLink(200, 200, 200);

cv::Point toPixel(const Eigen::Vector2d& point) {
    return {cvRound(point.x()), cvRound(point.y())};
}

}  // namespace

cv::Mat plotTouchDowns(const TouchScore& score, cv::Size displaySize) {
    cv::Mat image(displaySize, CV_8UC3, kBackground);
    const int dot = std::max(2, displaySize.width / 320);
    const int radius = std::max(dot + 1, cvRound(score.matchRadiusPx));
    for (const TrialOutcome& outcome : score.trials) {
        if (!outcome.found) {
            cv::circle(image, toPixel(outcome.truthDown), radius, kTruth, 1, cv::LINE_AA);
            continue;
        }
        cv::line(image, toPixel(outcome.truthDown), toPixel(outcome.detectedDown), kLink, 1, cv::LINE_AA);
    }
    for (const TrialOutcome& outcome : score.trials) {
        cv::circle(image, toPixel(outcome.truthDown), dot, kTruth, cv::FILLED, cv::LINE_AA);
        if (outcome.found)
            cv::circle(image, toPixel(outcome.detectedDown), dot, kDetected, cv::FILLED, cv::LINE_AA);
    }
    for (const PhantomTouch& phantom : score.phantoms)
        cv::drawMarker(image, toPixel(phantom.point), kDetected, cv::MARKER_CROSS, 4 * dot, 1, cv::LINE_AA);
    return image;
}

}  // namespace everytouch::eval
