#include "io/desktop_overlay.h"

#include <utility>

#include "io/kept_pattern.h"
#include "io/log.h"

namespace everytouch::io {

void DesktopOverlay::takeOutput(OpenedOutput output, std::uint64_t seed, int delta,
                                const std::filesystem::path& patternDirectory) {
    size_ = output.size;
    description_ = std::move(output.description);
    images_.setCode(keptPattern(seed, size_, patternDirectory), delta);
    images_.handOverCodeOverlay();
}

void DesktopOverlay::setDisplayToProjector(cv::Size displaySize, const Eigen::Matrix3d& displayToProjector) {
    checkOverlayDisplayToProjector(description_, size_, displaySize, displayToProjector);
}

void DesktopOverlay::show(const cv::Mat& projectorImage) {
    images_.handOverOpaque(projectorImage);
}

void DesktopOverlay::release() noexcept {
    try {
        images_.handOverCodeOverlay();
    } catch (const std::exception& error) {
        ET_LOG(Error) << description_
                      << ": the code over the desktop could not be drawn again: " << error.what();
    }
}

void DesktopOverlay::onProblemChange(std::function<void()> handler) {
    const std::lock_guard lock(handlerMutex_);
    problemHandler_ = std::move(handler);
}

void DesktopOverlay::problemChanged() {
    const std::lock_guard lock(handlerMutex_);
    if (problemHandler_)
        problemHandler_();
}

}  // namespace everytouch::io
