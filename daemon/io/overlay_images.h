#pragma once

#include <mutex>
#include <string>

#include <Eigen/Core>
#include <opencv2/core/mat.hpp>

namespace everytouch::io {

// The two images a code overlay alternates between, one per refresh, handed from the daemon's thread to the
// overlay's: the code over the desktop (core::makeCodeOverlay), or an opaque calibration image with the
// code embedded as the window projector embeds it. Premultiplied BGRA at the pattern's size, which is the
// output's. What an overlay does whatever display server it is drawn on.
class OverlayImages {
public:
    // Before the first hand-over: `pattern`, 0 or 1 per pixel of the output (CV_8UC1), `delta` 1..127,
    // checked by the caller. The overlay's thread may call takeNewest() before, and then gets nothing.
    void setCode(cv::Mat pattern, int delta);

    void handOverCodeOverlay();
    // Throws std::invalid_argument for an image of the wrong size or type (ProjectorOutput::show).
    void handOverOpaque(const cv::Mat& projectorImage);
    // On the overlay's thread: the pair handed over last, when one was since the last call.
    bool takeNewest(cv::Mat (&images)[2]);
    // On the overlay's thread: hands `images`, taken before, over again for a surface made anew, unless a
    // newer pair waits.
    void handOverAgain(cv::Mat (&images)[2]);

    const cv::Mat& pattern() const { return pattern_; }

private:
    void handOver(cv::Mat positive, cv::Mat negative);

    cv::Mat pattern_;
    int delta_ = 0;
    std::mutex mutex_;
    cv::Mat handedOver_[2];
    bool fresh_ = false;
};

// An overlay does not warp the desktop under it: warns, naming `description`, when a calibration draws the
// display through a keystone, since touches then land off their places until the table is calibrated
// through the overlay. Throws std::invalid_argument as ProjectorOutput::setDisplayToProjector.
void checkOverlayDisplayToProjector(const std::string& description, cv::Size outputSize, cv::Size displaySize,
                                    const Eigen::Matrix3d& displayToProjector);

}  // namespace everytouch::io
