#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include <Eigen/Core>

#include "core/contact.h"
#include "io/recording.h"

namespace everytouch::eval {

// The truth of each frame of a recording, in the recording's frame order: the fingers truth.csv lists for it.
using TruthFrames = std::vector<std::vector<core::FingerTruth>>;

// truth.csv arranged by the position of its frames; a line naming a frame the recording lacks is left out
// (io::Recording::open already checks the file's form).
TruthFrames truthFrames(const io::Recording& recording);

// One tap or drag: a maximal run of frames in which one finger's pad is on the table (truth height 0).
struct TouchTrial {
    std::uint32_t finger = 0;
    std::size_t first = 0;  // position of the first frame touching
    std::size_t last = 0;   // position of the last frame touching, inclusive
};

// Every trial of the truth, ordered by their first frame (then by finger).
std::vector<TouchTrial> touchTrials(const TruthFrames& truth);

// The truth of `finger` in a frame; nullptr when the frame does not list it.
const core::FingerTruth* findFinger(const std::vector<core::FingerTruth>& frame, std::uint32_t finger);

}  // namespace everytouch::eval
