#pragma once

#include <cstddef>
#include <optional>
#include <vector>

#include <opencv2/core/mat.hpp>

#include "core/frame.h"
#include "core/frame_pairer.h"
#include "eval/fingertip_scoring.h"
#include "io/recording.h"

namespace everytouch::eval {

// One pair of a recording with what a method sees of it and the truth it is scored against.
struct PairWithTruth {
    std::size_t position = 0;  // of the newer frame in the recording's frame list
    core::FramePair pair;
    cv::Mat texture;                  // T (core/code_image.h)
    cv::Mat subtraction;              // S
    cv::Mat truthMask;                // masks/ of the newer frame, CV_8UC1, 255 = hand
    std::vector<TruthPoint> fingers;  // truth.csv of the newer frame, in the camera's view
};

// The pairs of a recording as the daemon forms them (core::FramePairer: each frame with the previous one
// when that has the opposite polarity), each scored against the truth of its newer frame, whose time the
// pipeline reports it at.
class RecordingPairs {
public:
    // recording: must have masks.
    RecordingPairs(const io::Recording& recording, const TruthToCamera& truthToCamera);

    // The next pair in time order; false at the end.
    bool next(PairWithTruth& out);
    // The pair whose newer frame is at `position`; false when that frame does not pair.
    bool at(std::size_t position, PairWithTruth& out) const;

private:
    void complete(const core::FramePair& pair, std::size_t position, PairWithTruth& out) const;

    const io::Recording& recording_;
    const TruthToCamera& truthToCamera_;
    core::FramePairer pairer_;
    std::size_t nextPosition_ = 0;
};

}  // namespace everytouch::eval
