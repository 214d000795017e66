#pragma once

#include <functional>
#include <optional>
#include <string>

#include <Eigen/Core>
#include <opencv2/core/mat.hpp>
#include <opencv2/core/types.hpp>

namespace everytouch::io {

// The projector's side of the rig: where the desktop is drawn on the panel, and what the projector shows
// instead of it while a calibration needs it. A window, an external program, or the simulated rig. Called
// from one thread at a time (the calibration's while a job runs, the main thread otherwise).
class ProjectorOutput {
public:
    virtual ~ProjectorOutput() = default;

    // From now on the desktop, displaySize pixels, is drawn onto the panel through displayToProjector (H_dp,
    // the keystone of the calibration that became active), so that it appears where the daemon maps touches.
    // Throws std::invalid_argument for an empty size or a homography that is not finite and invertible.
    virtual void setDisplayToProjector(cv::Size displaySize, const Eigen::Matrix3d& displayToProjector) = 0;

    // Shows `projectorImage` (8-bit gray or BGR, size() pixels, one per projector pixel) until the next
    // show() or release(). Throws std::invalid_argument for an image of the wrong size or type.
    virtual void show(const cv::Mat& projectorImage) = 0;
    // Gives the projector back to the desktop (the content and its embedded code).
    virtual void release() noexcept = 0;
    // The projector panel, pixels.
    virtual cv::Size size() const = 0;
    virtual std::string describe() const = 0;
    // Whether the desktop reaches the panel through setDisplayToProjector's keystone. An overlay over the
    // desktop as it is does not warp it: a calibration made through it maps the display onto the whole panel.
    virtual bool drawsDisplayThroughKeystone() const { return true; }
    // Why the code is not on the table now, in words; nothing while it is. Safe to call from any thread.
    virtual std::optional<std::string> problem() const { return std::nullopt; }
    // `handler` is called, on the output's own thread, whenever problem() changes; an empty one ends the
    // calls before this returns.
    virtual void onProblemChange(std::function<void()> /*handler*/) {}
};

// Shows images on an output for as long as it lives and gives the projector back when it goes, however the
// calibration ends. Without an output (a recording shows what it shows) show() does nothing.
class ProjectorLease {
public:
    explicit ProjectorLease(ProjectorOutput* output) : output_(output) {}
    ~ProjectorLease() {
        if (output_ && shown_)
            output_->release();
    }
    ProjectorLease(const ProjectorLease&) = delete;
    ProjectorLease& operator=(const ProjectorLease&) = delete;

    void show(const cv::Mat& projectorImage) {
        if (!output_)
            return;
        shown_ = true;
        output_->show(projectorImage);
    }

private:
    ProjectorOutput* output_;
    bool shown_ = false;
};

}  // namespace everytouch::io
