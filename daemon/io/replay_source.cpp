#include "io/replay_source.h"

#include <thread>

namespace everytouch::io {

ReplaySource::ReplaySource(const std::filesystem::path& directory, bool paced)
    : directory_(directory), recording_(Recording::open(directory)), paced_(paced) {}

// A recording's frames are decoded into images of their own: no spare memory is used.
std::optional<core::Frame> ReplaySource::read(cv::Mat /*spare*/) {
    if (position_ >= recording_.frames().size())
        return std::nullopt;
    core::Frame frame = recording_.loadFrame(position_);
    if (paced_) {
        if (position_ == 0)
            start_ = std::chrono::steady_clock::now();
        const auto offset =
            std::chrono::microseconds(frame.timestampUs - recording_.frames().front().timestampUs);
        std::this_thread::sleep_until(start_ + offset);
    }
    ++position_;
    return frame;
}

std::optional<cv::Mat> ReplaySource::truthMask() const {
    if (!recording_.hasMasks())
        return std::nullopt;
    return position_ == 0 ? cv::Mat() : recording_.loadMask(position_ - 1);
}

}  // namespace everytouch::io
