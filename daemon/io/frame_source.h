#pragma once

#include <algorithm>
#include <cstdint>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include <opencv2/core/mat.hpp>

#include "core/contact.h"
#include "core/frame.h"
#include "io/rig_description.h"

namespace everytouch::io {

// Thrown by FrameSource::next when the source lost its camera (unplugged, powered off, its link down): the
// stream is not over, and a later call tries to reach the camera again.
class SourceLost : public std::runtime_error {
public:
    using std::runtime_error::runtime_error;
};

// How long a free-running camera at `frameRate` (0: unknown) may deliver no complete frame before it counts
// as lost: ten frame periods, kept between 0.3 s (a busy machine's pause is no lost camera, and taking one
// back costs seconds) and 0.4 s (a pulled cable must release the contacts and show within half a second);
// at least three periods for a camera slower than that; a second when the rate is unknown.
inline double cameraStallSeconds(double frameRate) {
    if (!(frameRate > 0.0))
        return 1.0;
    const double period = 1.0 / frameRate;
    return std::max(3.0 * period, std::clamp(10.0 * period, 0.3, 0.4));
}

// A stream of camera frames: a camera, the simulator or a recording. `next` blocks until the next frame
// (paced in real time unless the source was asked to run fast) and returns nothing at the end of the stream;
// it throws SourceLost while a camera cannot be reached, any other exception when the stream cannot go on.
class FrameSource {
public:
    virtual ~FrameSource() = default;

    // `spare`: the image of a frame the caller is done with; the new frame is written into its memory when
    // the size and type fit (the frame loop gives such buffers back, so that a steady stream allocates no
    // frame memory). Empty: the source allocates.
    std::optional<core::Frame> next(cv::Mat spare = cv::Mat()) { return read(std::move(spare)); }

    // The rig's own description when the source knows it (simulator, recording); cameras rely on the
    // calibration store instead.
    virtual std::optional<RigDescription> rig() const = 0;

    virtual std::string describe() const = 0;

    // The frames per second a camera runs at, as it says; 0 when it does not (a trigger, a rig that
    // describes itself).
    virtual double frameRate() const { return 0.0; }

    // Frames the source lost before they reached `next` (a camera's incomplete or skipped frames); safe to
    // call from any thread.
    virtual std::uint64_t droppedFrames() const { return 0; }

    // Ground truth of the frame `next` returned last, when the source knows it (the simulator): one entry per
    // finger the scene presents over the display, possibly none. Nothing for sources without ground truth.
    virtual std::optional<std::vector<core::FingerTruth>> truth() const { return std::nullopt; }

    // Ground-truth hand mask of the frame `next` returned last, when the source knows it (the simulator, a
    // recording with masks): CV_8UC1, camera size, 255 where the camera sees a hand; empty before the first
    // frame. It may share its pixels with the source, so it holds only until the next call of `next`.
    // Nothing for sources without masks.
    virtual std::optional<cv::Mat> truthMask() const { return std::nullopt; }

private:
    // What next() does; `spare` as there.
    virtual std::optional<core::Frame> read(cv::Mat spare) = 0;
};

}  // namespace everytouch::io
