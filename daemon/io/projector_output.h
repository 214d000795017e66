#pragma once

#include <string>

#include <opencv2/core/mat.hpp>
#include <opencv2/core/types.hpp>

namespace everytouch::io {

// What the projector shows instead of the desktop while a calibration needs it: a window, an external
// program, or the simulated rig. Called from one thread at a time (the calibration's).
class ProjectorOutput {
public:
    virtual ~ProjectorOutput() = default;

    // Shows `projectorImage` (8-bit gray or BGR, size() pixels, one per projector pixel) until the next
    // show() or release(). Throws std::invalid_argument for an image of the wrong size or type.
    virtual void show(const cv::Mat& projectorImage) = 0;
    // Gives the projector back to the desktop (the content and its embedded code).
    virtual void release() noexcept = 0;
    // The projector panel, pixels.
    virtual cv::Size size() const = 0;
    virtual std::string describe() const = 0;
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
