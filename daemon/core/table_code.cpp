#include "core/table_code.h"

#include <cmath>

#include <opencv2/imgproc.hpp>

#include "core/camera_model.h"
#include "core/geometry.h"

namespace everytouch::core {

namespace {

double footprintAtCentre(const Calibration& calibration) {
    const Eigen::Matrix3d toProjector = calibration.cameraToProjectorHomography(0.0);
    const Eigen::Vector2d centre(calibration.cameraSize.width / 2.0, calibration.cameraSize.height / 2.0);
    const Eigen::Vector2d p = applyHomography(toProjector, centre);
    const Eigen::Vector2d dx = applyHomography(toProjector, centre + Eigen::Vector2d(1, 0)) - p;
    const Eigen::Vector2d dy = applyHomography(toProjector, centre + Eigen::Vector2d(0, 1)) - p;
    return std::sqrt(0.5 * (dx.squaredNorm() + dy.squaredNorm()));
}

}  // namespace

TableCode predictTableCode(const Calibration& calibration, const cv::Mat& pattern, double cameraBlurPx) {
    CV_Assert(pattern.type() == CV_8UC1 && !pattern.empty());
    TableCode code;
    code.projectorPixelsPerCameraPixel = footprintAtCentre(calibration);

    // The panel blurred by the camera pixel's footprint first, so that resampling does not alias the code.
    cv::Mat panel;
    pattern.convertTo(panel, CV_32FC1);
    const double footprintSigma = kBoxSigmaPerWidth * code.projectorPixelsPerCameraPixel;
    cv::GaussianBlur(panel, panel, cv::Size(), footprintSigma);

    // Frames come as the camera sees them, through its lens distortion: each raw pixel's ray meets the table
    // where the undistorted pixel's homography says.
    const CameraModel camera{calibration.cameraMatrix, calibration.cameraDistortion};
    const Eigen::Matrix3d cameraToProjector = calibration.cameraToProjectorHomography(0.0);
    cv::Mat mapX(calibration.cameraSize, CV_32FC1), mapY(calibration.cameraSize, CV_32FC1);
    for (int y = 0; y < mapX.rows; ++y)
        for (int x = 0; x < mapX.cols; ++x) {
            const Eigen::Vector2d p =
                applyHomography(cameraToProjector, camera.undistortPixel(Eigen::Vector2d(x, y)));
            mapX.at<float>(y, x) = static_cast<float>(p.x());
            mapY.at<float>(y, x) = static_cast<float>(p.y());
        }
    // Camera pixels the panel does not light get -1: no code can match there.
    cv::remap(panel, code.predicted, mapX, mapY, cv::INTER_LINEAR, cv::BORDER_CONSTANT, cv::Scalar(-1.0));
    const double pixelSigma = std::hypot(kBoxSigmaPerWidth, cameraBlurPx);
    cv::Mat outside = code.predicted < 0;
    cv::GaussianBlur(code.predicted, code.predicted, cv::Size(), pixelSigma);
    cv::dilate(outside, outside, cv::Mat(), cv::Point(-1, -1), 2);
    code.predicted.setTo(-1.0, outside);
    return code;
}

}  // namespace everytouch::core
