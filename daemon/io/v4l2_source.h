#pragma once

#include <atomic>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <opencv2/core/types.hpp>

#include "io/camera_settings.h"
#include "io/frame_source.h"
#include "io/handles.h"
#include "io/v4l2_pixels.h"

namespace everytouch::io {

// A camera through Video4Linux2 (USB Video Class webcams, capture cards, most USB industrial cameras), read
// from memory-mapped buffers of the driver's: each frame is converted once out of its buffer, which goes
// straight back to the driver. Buffers the driver marks as damaged and gaps in its frame sequence are
// counted as dropped and never delivered. Frames carry the driver's monotonic timestamps and alternate in
// polarity by their place in the driver's count, as AravisSource's do.
class V4l2Source final : public FrameSource {
public:
    // `device`: the node, e.g. /dev/video0. Throws InputError naming `input` (the --rig value) when the node
    // is no camera or the camera refuses a setting, and std::runtime_error, which a later attempt may not
    // meet, when the node cannot be opened or does not stream.
    V4l2Source(const std::string& input, const std::string& device, const CameraSettings& settings);
    V4l2Source(const V4l2Source&) = delete;
    V4l2Source& operator=(const V4l2Source&) = delete;

    // Throws SourceLost when the camera went away or no frame came for stallTimeoutSeconds(), and in each
    // later call until the node opens again with its settings.
    std::optional<RigDescription> rig() const override { return std::nullopt; }
    std::string describe() const override { return description_; }
    double frameRate() const override { return frameRate_; }
    std::uint64_t droppedFrames() const override { return dropped_.load(); }

    // How long next() waits for a frame before the camera counts as lost: ten frame periods, at least half a
    // second.
    double stallTimeoutSeconds() const;

private:
    std::optional<core::Frame> read(cv::Mat spare) override;

    // Opens the node, applies the settings and starts streaming; throws as the constructor does.
    void connect();
    void release();
    [[noreturn]] void lose(const std::string& problem);

    std::string input_;
    std::string device_;
    CameraSettings settings_;
    UniqueFd fd_;
    std::vector<MemoryMapping> buffers_;  // after fd_: unmapped before the node closes
    V4l2Pixels pixels_ = V4l2Pixels::Yuyv;
    cv::Size size_;
    std::size_t bytesPerLine_ = 0;
    double frameRate_ = 0.0;
    std::string description_;
    std::optional<std::uint32_t> lastSequence_;
    std::uint64_t nextIndex_ = 0;
    std::atomic<std::uint64_t> dropped_{0};
};

}  // namespace everytouch::io
