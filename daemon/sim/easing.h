#pragma once

#include <algorithm>

namespace everytouch::sim {

// Ken Perlin's smootherstep: 0 below 0, 1 above 1, and between them an S whose first and second
// derivatives vanish at both ends, so that a hand eased by it starts and stops without a jolt.
inline double smootherStep(double x) {
    x = std::clamp(x, 0.0, 1.0);
    return x * x * x * (x * (6.0 * x - 15.0) + 10.0);
}

}  // namespace everytouch::sim
