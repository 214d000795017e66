#pragma once

#include <chrono>
#include <filesystem>
#include <optional>

#include "io/frame_source.h"
#include "io/recording.h"

namespace everytouch::io {

// Plays a recording directory back, at its recorded pace or as fast as frames can be read.
class ReplaySource final : public FrameSource {
public:
    ReplaySource(const std::filesystem::path& directory, bool paced);

    std::optional<RigDescription> rig() const override { return recording_.rig(); }
    std::string describe() const override { return "replay of " + directory_.string(); }
    // Read from the recording on each call, so a replay nobody asks for masks reads none.
    std::optional<cv::Mat> truthMask() const override;

    const Recording& recording() const { return recording_; }

private:
    std::optional<core::Frame> read(cv::Mat spare) override;

    std::filesystem::path directory_;
    Recording recording_;
    bool paced_;
    std::size_t position_ = 0;
    std::chrono::steady_clock::time_point start_;
};

}  // namespace everytouch::io
