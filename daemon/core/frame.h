#pragma once

#include <cstdint>

#include <opencv2/core.hpp>

namespace everytouch::core {

// Which of the two projected images a camera frame shows: +1 for I = O + P, -1 for I' = O - P.
enum class Polarity : int { Positive = 1, Negative = -1 };

constexpr Polarity opposite(Polarity p) {
    return p == Polarity::Positive ? Polarity::Negative : Polarity::Positive;
}

// One camera exposure. `image` is 8-bit gray (CV_8UC1) or BGR (CV_8UC3), undistorted or not as the camera
// gives it.
struct Frame {
    cv::Mat image;
    std::int64_t timestampUs = 0;  // capture time, microseconds, monotonic within one source
    std::uint64_t index = 0;       // position in the source's stream, starting at 0
    Polarity polarity = Polarity::Positive;
};

// Two consecutive frames of opposite polarity, reported at the time of the newer one.
struct FramePair {
    Frame positive;  // C: camera image of O + P
    Frame negative;  // C': camera image of O - P

    const Frame& latest() const { return positive.index > negative.index ? positive : negative; }
};

}  // namespace everytouch::core
