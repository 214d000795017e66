#pragma once

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "io/frame_source.h"
#include "io/rig_spec.h"
#include "sim/renderer.h"
#include "sim/simulator.h"

namespace everytouch::io {

// The simulated rig as a frame source (`--rig sim[:SCENARIO][,key=value...]`): frames at the camera's rate
// with alternating polarity, paced in real time unless asked to run fast, with the ground truth of each.
class SimSource final : public FrameSource {
public:
    // Throws InputError naming the --rig spec and the key at fault (unknown scenario or key, bad value,
    // unreadable content image).
    SimSource(const RigSpec& spec, bool paced);

    std::optional<RigDescription> rig() const override;
    std::string describe() const override;
    // Without duration= the stream has no end.
    bool endless() const { return !simulator_->endFrame(); }
    std::optional<std::vector<core::FingerTruth>> truth() const override;
    // The renderer's mask itself, rewritten by the next frame.
    std::optional<cv::Mat> truthMask() const override { return truth_.handMask; }

    // Everything the renderer knows about the last frame: every fingertip, the hand mask, visible heights.
    const sim::FrameTruth& frameTruth() const { return truth_; }

    // What the simulated projector shows from the next frame on instead of the content (8-bit gray or BGR,
    // projector size); an empty image returns to the content. Safe to call while another thread takes
    // frames. Throws std::invalid_argument for another size or type.
    void projectImage(const cv::Mat& projectorImage);
    cv::Size projectorSize() const { return simulator_->calibration().projectorSize; }
    // From the next frame on the desktop is drawn through the daemon's keystone (sim::Simulator::
    // setDisplayToProjector); rig() and truth() then describe that display. Safe to call while another thread
    // takes frames. Throws std::invalid_argument for an empty size or a homography that is not invertible.
    void setDisplayToProjector(cv::Size displaySize, const Eigen::Matrix3d& displayToProjector);

private:
    std::optional<core::Frame> read(cv::Mat spare) override;

    std::string spec_;
    std::unique_ptr<sim::Simulator> simulator_;
    // The renderer, for one thread at a time: the camera thread renders while the calibration changes the
    // projected image and the daemon the keystone. Those go first (betweenFrames): a camera thread rendering
    // back to back would otherwise take the mutex again before a waiting thread wakes up, for seconds.
    std::unique_lock<std::mutex> betweenFrames() const;
    // Whether frame `index` falls in a camera fault that begins `fromS` into the session and lasts `forS`.
    bool faultAt(std::uint64_t index, std::optional<double> fromS, double forS) const;
    mutable std::mutex renderMutex_;
    mutable std::condition_variable othersDone_;
    mutable std::atomic<int> othersWaiting_{0};
    bool paced_;
    std::uint64_t index_ = 0;
    std::optional<std::chrono::steady_clock::time_point> start_;  // when frame 0 would have come, once paced
    sim::FrameTruth truth_;
    std::uint64_t truthIndex_ = 0;
    cv::Size truthDisplaySize_;  // the display the last frame showed
};

}  // namespace everytouch::io
