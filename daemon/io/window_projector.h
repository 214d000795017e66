#pragma once

#include <cstdint>
#include <filesystem>
#include <future>
#include <mutex>
#include <string>

#include "io/output_thread.h"
#include "io/projector_output.h"

namespace everytouch::io {

// The projector as a borderless fullscreen window of the daemon's own on one output of the display server
// (X11, Wayland, or the console's KMS when no display server runs). Everything it shows carries the code as
// the paper embeds it: it alternates between I = O + P and I' = O - P on every refresh. Between calibration
// images O is the display area in white (through the keystone once one is known) and black around it, so a
// camera rig detects touches there; the desktop on that output stays covered while the window is up.
//
// SDL lives on the window's own thread; the calls below only hand it new images. Called from one thread at a
// time, as every ProjectorOutput.
class WindowProjector final : public ProjectorOutput {
public:
    // Opens the window on `display`: a display's name as the display server gives it (an X11 RandR output's
    // name or its monitor's) or its number from 0; empty for the first. The code is the pattern of `seed` at
    // the output's size, `delta` levels strong (1..127). Throws InputError naming [Projector] Display= for a
    // display that does not exist (listing those that do), std::runtime_error when no display server is
    // reachable or the window cannot be made. Generating the pattern takes a minute at 1920x1080: once
    // generated it is kept in `patternDirectory` (empty: nowhere) and read from there at the next start.
    WindowProjector(const std::string& display, std::uint64_t seed, int delta,
                    const std::filesystem::path& patternDirectory);
    ~WindowProjector() override;
    WindowProjector(const WindowProjector&) = delete;
    WindowProjector& operator=(const WindowProjector&) = delete;

    void setDisplayToProjector(cv::Size displaySize, const Eigen::Matrix3d& displayToProjector) override;
    void show(const cv::Mat& projectorImage) override;
    void release() noexcept override;
    cv::Size size() const override { return size_; }
    std::string describe() const override { return description_; }

    // The code every image carries: 0 or 1 per projector pixel (CV_8UC1, size()).
    const cv::Mat& pattern() const { return pattern_; }

private:
    void run(const std::string& display, std::promise<OpenedOutput>& opened);
    // The white display area through the keystone, black around it.
    cv::Mat idleImage() const;
    void embedAndHandOver(const cv::Mat& content);

    cv::Size size_;
    std::string description_;
    cv::Mat pattern_;
    int delta_;
    cv::Size displaySize_;
    Eigen::Matrix3d displayToProjector_ = Eigen::Matrix3d::Identity();
    bool showing_ = false;  // a calibration image, not the idle display

    std::mutex handOverMutex_;
    cv::Mat handedOver_[2];  // the next I and I', taken by the window's thread
    bool fresh_ = false;

    OutputThread thread_;  // last: it stops before what it draws from goes away
};

}  // namespace everytouch::io
