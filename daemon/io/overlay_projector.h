#pragma once

#include <atomic>
#include <cstdint>
#include <filesystem>
#include <future>
#include <mutex>
#include <string>

#include "io/output_thread.h"
#include "io/projector_output.h"

namespace everytouch::io {

// The code over the desktop as it is, on X11: a topmost, input-transparent, translucent window over one
// output, which the compositing manager blends over everything on every refresh, alternating between the two
// images of core::makeCodeOverlay (Present paces them, one per refresh). People see the desktop and use it as
// always; the camera's subtraction of two frames sees the code. A calibration image is shown opaque in the
// same window, with the code embedded as the window projector embeds it, until release().
//
// Without a compositing manager the overlay's pixels would cover the desktop as they are, so it needs one at
// start, hides while none runs and comes back when one does. The desktop is not warped (no keystone): a
// calibration made through it maps the display onto the whole output.
//
// Xlib lives on the overlay's own thread; the calls below only hand it new images. Called from one thread at
// a time, as every ProjectorOutput.
class OverlayProjector final : public ProjectorOutput {
public:
    // Opens the overlay on the X server of DISPLAY over `display`: a RandR monitor's name or its number from
    // 0; empty for the first. The code is the pattern of `seed` at the monitor's size, `delta` levels strong
    // (1..127), kept in `patternDirectory` as the window projector keeps it. Throws InputError naming
    // [Projector] Display= for a monitor that does not exist (listing those that do) and for a bad delta,
    // std::runtime_error when no X server is reachable, it lacks what the overlay needs (a 32-bit visual,
    // Present, SHAPE, XFixes), or no compositing manager runs.
    OverlayProjector(const std::string& display, std::uint64_t seed, int delta,
                     const std::filesystem::path& patternDirectory);
    ~OverlayProjector() override;
    OverlayProjector(const OverlayProjector&) = delete;
    OverlayProjector& operator=(const OverlayProjector&) = delete;

    void setDisplayToProjector(cv::Size displaySize, const Eigen::Matrix3d& displayToProjector) override;
    void show(const cv::Mat& projectorImage) override;
    void release() noexcept override;
    cv::Size size() const override { return size_; }
    std::string describe() const override { return description_; }
    bool drawsDisplayThroughKeystone() const override { return false; }
    std::optional<std::string> problem() const override;
    void onProblemChange(std::function<void()> handler) override;

    // The code: 0 or 1 per projector pixel (CV_8UC1, size()).
    const cv::Mat& pattern() const { return pattern_; }
    // Refreshes that showed one of the two images so far, and whether the overlay is up.
    std::uint64_t presented() const { return thread_.presented(); }
    bool visible() const { return visible_; }

private:
    class Connection;
    void run(const std::string& display, std::promise<OpenedOutput>& opened);
    void handOver(cv::Mat positive, cv::Mat negative);
    void handOverCodeOverlay();

    cv::Size size_;
    std::string description_;
    cv::Mat pattern_;
    int delta_;

    std::mutex handOverMutex_;
    cv::Mat handedOver_[2];  // the next two images (premultiplied BGRA), taken by the overlay's thread
    bool fresh_ = false;

    std::atomic<bool> visible_{false};
    std::atomic<bool> compositorGone_{false};  // the overlay hides meanwhile
    std::mutex problemMutex_;
    std::function<void()> problemHandler_;
    OutputThread thread_;  // last: it stops before what it draws from goes away
};

}  // namespace everytouch::io
