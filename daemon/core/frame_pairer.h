#pragma once

#include <optional>

#include "core/frame.h"

namespace everytouch::core {

// Pairs each new frame with the previous frame when that one has the opposite polarity, so a 120 Hz camera
// gives 120 pairs per second. A repeated polarity (a dropped frame) restarts pairing from the new frame.
class FramePairer {
public:
    std::optional<FramePair> push(const Frame& frame);
    void reset() { previous_.reset(); }

private:
    std::optional<Frame> previous_;
};

}  // namespace everytouch::core
