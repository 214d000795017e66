#pragma once

#include <cstdint>
#include <filesystem>
#include <functional>
#include <mutex>
#include <string>

#include "io/output_thread.h"
#include "io/overlay_images.h"
#include "io/projector_output.h"

namespace everytouch::io {

// What the overlays over the desktop as it is share, whatever display server draws them: the code of
// core::makeCodeOverlay over the desktop, or a calibration image shown opaque with the code embedded, until
// release(); the desktop is not warped (no keystone), so a calibration made through an overlay maps the
// display onto the whole output. The display server's side (the overlay's thread) takes the images from
// images_.
class DesktopOverlay : public ProjectorOutput {
public:
    void setDisplayToProjector(cv::Size displaySize, const Eigen::Matrix3d& displayToProjector) override;
    void show(const cv::Mat& projectorImage) override;
    void release() noexcept override;
    cv::Size size() const override { return size_; }
    std::string describe() const override { return description_; }
    bool drawsDisplayThroughKeystone() const override { return false; }
    void onProblemChange(std::function<void()> handler) override;

    // The code: 0 or 1 per projector pixel (CV_8UC1, size()).
    const cv::Mat& pattern() const { return images_.pattern(); }

protected:
    // Once the overlay's thread opened `output`: the code is the pattern of `seed` at its size, `delta`
    // levels strong, kept in `patternDirectory` as the window projector keeps it, and goes over the desktop.
    void takeOutput(OpenedOutput output, std::uint64_t seed, int delta,
                    const std::filesystem::path& patternDirectory);

    // On the overlay's thread, when problem() changed: tells the handler.
    void problemChanged();

    OverlayImages images_;

private:
    cv::Size size_;
    std::string description_;
    std::mutex handlerMutex_;
    std::function<void()> problemHandler_;
};

}  // namespace everytouch::io
