#pragma once

#include <opencv2/core/types.hpp>

namespace everytouch::io {

// The absolute axes of the virtual touchscreen. A unit is a fixed fraction of a display pixel, fine enough
// that the whole number of units per millimetre evdev carries as the axis resolution is within 0.5 % of the
// true scale even on a large table lit by few pixels; libinput then reports the projected image's real size
// and positions in millimetres. Positions map linearly, as every compositor maps a touchscreen onto its
// output.
struct TouchscreenAxes {
    int unitsPerPixel = 1;  // axis units per display pixel, the same on both axes
    int maximumX = 0;       // largest x, units; the minimum is 0
    int maximumY = 0;       // largest y, units; the minimum is 0
    int resolutionX = 1;    // units per mm along x
    int resolutionY = 1;    // units per mm along y

    // Axes for a display of `displaySize` pixels projected onto `displaySizeMm` of table. Throws InputError
    // naming the calibration field when either size is unusable.
    static TouchscreenAxes forDisplay(cv::Size displaySize, cv::Size2d displaySizeMm);

    // A finite display position in pixels as axis units, clamped to the axis range.
    int unitsX(double xPx) const;
    int unitsY(double yPx) const;

    // The size a client computes from the axes: (maximum - minimum) / resolution.
    cv::Size2d sizeMm() const;

    bool operator==(const TouchscreenAxes&) const = default;
};

}  // namespace everytouch::io
