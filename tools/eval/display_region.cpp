#include "eval/display_region.h"

#include <vector>

#include <opencv2/imgproc.hpp>

#include "core/camera_model.h"
#include "core/geometry.h"

namespace everytouch::eval {

namespace {

// Points per display edge: enough for the outline to follow the lens distortion.
constexpr int kSamplesPerEdge = 32;

}  // namespace

cv::Mat displayRegion(const core::Calibration& calibration) {
    const core::CameraModel camera{calibration.cameraMatrix, calibration.cameraDistortion};
    const Eigen::Matrix3d displayToCamera =
        calibration.tableToCameraHomography() * calibration.displayToTableHomography();
    const double width = calibration.displaySize.width, height = calibration.displaySize.height;
    const Eigen::Vector2d corners[] = {{0, 0}, {width, 0}, {width, height}, {0, height}};
    std::vector<cv::Point> outline;
    for (int edge = 0; edge < 4; ++edge)
        for (int i = 0; i < kSamplesPerEdge; ++i) {
            const Eigen::Vector2d display =
                corners[edge] + (corners[(edge + 1) % 4] - corners[edge]) * (double(i) / kSamplesPerEdge);
            const Eigen::Vector2d raw = camera.distortPixel(core::applyHomography(displayToCamera, display));
            outline.emplace_back(cvRound(raw.x()), cvRound(raw.y()));
        }
    cv::Mat region(calibration.cameraSize, CV_8UC1, cv::Scalar(0));
    cv::fillPoly(region, std::vector<std::vector<cv::Point>>{outline}, cv::Scalar(255));
    return region;
}

}  // namespace everytouch::eval
