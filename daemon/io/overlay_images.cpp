#include "io/overlay_images.h"

#include <utility>

#include <opencv2/imgproc.hpp>

#include "core/code_overlay.h"
#include "core/embedding.h"
#include "core/keystone.h"
#include "io/log.h"
#include "io/projector_image.h"

namespace everytouch::io {

namespace {

cv::Mat opaque(const cv::Mat& bgr) {
    cv::Mat bgra;
    cv::cvtColor(bgr, bgra, cv::COLOR_BGR2BGRA);
    return bgra;
}

}  // namespace

void OverlayImages::setCode(cv::Mat pattern, int delta) {
    pattern_ = std::move(pattern);
    delta_ = delta;
}

void OverlayImages::handOverCodeOverlay() {
    cv::Mat positive, negative;
    core::makeCodeOverlay(pattern_, delta_, positive, negative);
    handOver(std::move(positive), std::move(negative));
}

void OverlayImages::handOverOpaque(const cv::Mat& projectorImage) {
    cv::Mat positive, negative;
    core::embedCode(projectorImageInColour(projectorImage, pattern_.size()), pattern_, delta_, positive,
                    negative);
    handOver(opaque(positive), opaque(negative));
}

bool OverlayImages::takeNewest(cv::Mat (&images)[2]) {
    const std::lock_guard lock(mutex_);
    if (!fresh_)
        return false;
    std::swap(images[0], handedOver_[0]);
    std::swap(images[1], handedOver_[1]);
    fresh_ = false;
    return true;
}

void OverlayImages::handOverAgain(cv::Mat (&images)[2]) {
    const std::lock_guard lock(mutex_);
    if (fresh_ || images[0].empty())
        return;
    std::swap(images[0], handedOver_[0]);
    std::swap(images[1], handedOver_[1]);
    fresh_ = true;
}

void OverlayImages::handOver(cv::Mat positive, cv::Mat negative) {
    const std::lock_guard lock(mutex_);
    handedOver_[0] = std::move(positive);
    handedOver_[1] = std::move(negative);
    fresh_ = true;
}

void checkOverlayDisplayToProjector(const std::string& description, cv::Size outputSize, cv::Size displaySize,
                                    const Eigen::Matrix3d& displayToProjector) {
    core::checkDisplayToProjector(displaySize, displayToProjector);
    const Eigen::Matrix3d normalised = displayToProjector / displayToProjector(2, 2);
    Eigen::Matrix3d scale = Eigen::Matrix3d::Identity();
    scale(0, 0) = static_cast<double>(outputSize.width) / displaySize.width;
    scale(1, 1) = static_cast<double>(outputSize.height) / displaySize.height;
    if (!normalised.isApprox(scale, 1e-6))
        ET_LOG(Warning)
            << description
            << ": the calibration draws the display through a keystone, and the desktop under the "
               "overlay is not warped: touches land off their places until the table is calibrated "
               "through the overlay (everytouch-calib calibrate table)";
}

}  // namespace everytouch::io
