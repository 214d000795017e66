#pragma once

#include <algorithm>
#include <vector>

namespace everytouch::core {

// The targets of the paper's accuracy test (section VII, Fig. 15(a)): 35 circles, 7 columns by 5 rows,
// spread evenly over the display. The simulated projector draws them, the simulated hand taps their
// centres, and everytouch-calib scores taps against them; this is their one definition. It needs nothing but
// the standard library, so that everytouch-calib, which does not link the pipeline, can include it.

// A point on the display, display pixels.
struct DisplayPoint {
    double x = 0.0;
    double y = 0.0;
};

inline constexpr int kAccuracyGridColumns = 7;
inline constexpr int kAccuracyGridRows = 5;

// The circles' centres, row by row from the top left, display pixels: column c at (c + 1) / 8 of the width,
// row r at (r + 1) / 6 of the height, so that the gaps between circles equal those to the display's edges.
inline std::vector<DisplayPoint> accuracyGridCentres(double displayWidth, double displayHeight) {
    std::vector<DisplayPoint> centres;
    centres.reserve(kAccuracyGridColumns * kAccuracyGridRows);
    for (int row = 0; row < kAccuracyGridRows; ++row)
        for (int column = 0; column < kAccuracyGridColumns; ++column)
            centres.push_back({displayWidth * (column + 1) / (kAccuracyGridColumns + 1),
                               displayHeight * (row + 1) / (kAccuracyGridRows + 1)});
    return centres;
}

// The radius of the drawn circles, display pixels: 4.5 % of the display's shorter side (22 px on the paper's
// 640 x 480 display), about a fingertip's width across.
inline double accuracyGridCircleRadius(double displayWidth, double displayHeight) {
    return 0.045 * std::min(displayWidth, displayHeight);
}

}  // namespace everytouch::core
