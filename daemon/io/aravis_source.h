#pragma once

#include <atomic>
#include <cstdint>
#include <optional>
#include <string>
#include <thread>

#include <arv.h>

#include "io/camera_pixels.h"
#include "io/camera_settings.h"
#include "io/frame_source.h"
#include "io/gobject_handles.h"

namespace everytouch::io {

// How many frames a camera counted between frame ids `last` and `next` that did not arrive: GigE Vision's
// 16-bit counter wraps from 65535 to 1; a counter that jumps back or by more than 1000 started over (0).
std::uint64_t framesMissedBetween(std::uint64_t last, std::uint64_t next);

// A GenICam camera through Aravis (GigE Vision, USB3 Vision), free running or on a trigger line. Each frame
// is copied once out of the stream's buffer, which goes straight back to the stream. Buffers the camera or
// the link did not complete, and frames missing from the camera's frame counter, are counted as dropped and
// never delivered. Frames carry the camera's timestamps and alternate in polarity by their place in the
// camera's count; which of them really shows O + P, detection reads from the code (core/polarity_lock.h).
class AravisSource final : public FrameSource {
public:
    // `id` as arv-tool-0.8 lists it, or a GigE camera's address; empty: the first camera found. Throws
    // InputError naming `input` (the --rig value) when the camera refuses a setting or offers no pixel format
    // we read, and std::runtime_error, which a later attempt may not meet, when no camera answers or it
    // does not stream.
    AravisSource(const std::string& input, const std::string& id, const CameraSettings& settings);
    ~AravisSource() override;
    AravisSource(const AravisSource&) = delete;
    AravisSource& operator=(const AravisSource&) = delete;

    // Throws SourceLost when no complete frame came for stallTimeoutSeconds(), and in each later call until
    // the camera answers again with its settings.
    // A camera describes only itself: the calibration store and the projector side know the rest.
    std::optional<RigDescription> rig() const override { return std::nullopt; }
    std::string describe() const override { return description_; }
    double frameRate() const override { return frameRate_; }
    std::uint64_t droppedFrames() const override { return dropped_.load(); }

    // How long next() waits for a frame before the camera counts as lost: ten frame periods, at least half a
    // second; two seconds on a trigger.
    double stallTimeoutSeconds() const;

private:
    std::optional<core::Frame> read(cv::Mat spare) override;

    // Opens the camera, applies the settings and starts it; throws as the constructor does.
    void connect();
    // Lets go of a camera that stopped delivering, without waiting for it.
    void releaseLostCamera();

    std::string input_;
    std::string id_;
    CameraSettings settings_;
    GObjectHandle<ArvCamera> camera_;
    GObjectHandle<ArvStream> stream_;
    CameraPixels pixels_ = CameraPixels::Mono8;
    double frameRate_ = 0.0;
    std::string description_;
    std::string trigger_;  // the trigger source frames wait for; empty when free running
    std::optional<std::uint64_t> lastFrameId_;
    std::uint64_t nextIndex_ = 0;
    std::thread releaser_;  // lets go of a lost camera's handles
    std::atomic<std::uint64_t> dropped_{0};
};

}  // namespace everytouch::io
