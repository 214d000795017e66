#pragma once

#include <cstdint>
#include <vector>

#include <opencv2/core/mat.hpp>

#include "core/frame.h"
#include "core/table_code.h"

namespace everytouch::core {

// Which frame of a pair shows O + P, read from the code itself. A camera that runs freely beside the
// projector labels its frames by their place in its stream, so half the time it starts on an O - P frame,
// and a refresh the projector misses, or a frame the camera loses without a gap in its counter, swaps the
// order from then on. S made the wrong way round is the code negated: its correlation with the table's code
// predicted through the calibration is as strongly negative as it is positive otherwise. Each pair is
// checked; only a significant negative correlation swaps the order, so a pair that shows no code (two frames
// of the same polarity, a dark room, a projector showing black) leaves it as it was.
class PolarityLock {
public:
    // The table's code as the camera sees it, and where to look for it (CV_8UC1, camera size, nonzero on the
    // display). Keeps whether the frames are swapped: the camera's order does not change with the rig.
    void setRig(const TableCode& tableCode, const cv::Mat& region);

    // True when the pair's frames are to be taken the other way round: the polarity of the frame labelled
    // Positive is really Negative.
    bool swapped() const { return swapped_; }

    // S made from a pair taken as swapped() says (CV_16SC1, camera size). Returns true when its code has the
    // wrong sign: swapped() has then changed, and S is to be made again from the pair taken the other way.
    bool relock(const cv::Mat& subtraction);

    // The last pair's correlation of S with the table's code (-1..1), and one standard deviation of it when
    // nothing correlates: a sign is believed beyond kSignificance of those.
    double correlation() const { return correlation_; }
    double chance() const { return chance_; }
    // How often the order has been swapped since the start.
    std::uint64_t swaps() const { return swaps_; }

    static constexpr double kSignificance = 5.0;

private:
    // Runs of kRunPx pixels along every kRowStep-th row where the code is predicted: each run's own means are
    // taken out, so that the content's brightness, which changes the code's amplitude, does not count.
    struct Run {
        int y = 0, x = 0;
    };
    static constexpr int kRunPx = 8;
    static constexpr int kRowStep = 8;
    std::vector<Run> runs_;
    std::vector<float> predicted_;  // kRunPx values per run, less their mean
    double predictedSquares_ = 0.0;
    bool swapped_ = false;
    double correlation_ = 0.0;
    double chance_ = 1.0;
    std::uint64_t swaps_ = 0;
};

// The pair with its frames taken the other way round (headers only: no pixel is copied).
FramePair swappedPair(const FramePair& pair);

}  // namespace everytouch::core
