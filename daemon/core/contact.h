#pragma once

#include <cstdint>
#include <vector>

namespace everytouch::core {

// A finger the system reports, in display pixels. Hovering fingers are reported with touching = false.
struct Contact {
    std::uint32_t id = 0;   // stable while the finger is tracked
    double x = 0.0;         // display pixels
    double y = 0.0;         // display pixels
    bool touching = false;  // true when the finger is at or below the configured touch height
    double heightMm = 0.0;  // estimated height of the finger pad above the table
    bool palm = false;      // a resting palm or hand side, reported so sinks can cancel it

    bool operator==(const Contact&) const = default;
};

using Contacts = std::vector<Contact>;

// Ground truth for one finger in one frame, as a renderer knows it.
struct FingerTruth {
    std::uint64_t frameIndex = 0;
    std::uint32_t id = 0;
    double x = 0.0;         // fingertip contact point, display pixels
    double y = 0.0;         // display pixels
    double heightMm = 0.0;  // height of the finger pad above the table; 0 when touching

    bool operator==(const FingerTruth&) const = default;
};

}  // namespace everytouch::core
