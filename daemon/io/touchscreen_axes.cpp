#include "io/touchscreen_axes.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "io/input_error.h"

namespace everytouch::io {

namespace {

// A unit no larger than 0.01 mm keeps the rounding of the integer resolution below 0.5 %.
constexpr double kMinimumUnitsPerMm = 100.0;
// Far beyond any display, far below where axis values would overflow an int.
constexpr double kLargestAxisUnits = 1 << 30;

int toUnits(double px, int unitsPerPixel, int maximum) {
    const double units = std::round(px * unitsPerPixel);
    return static_cast<int>(std::clamp(units, 0.0, static_cast<double>(maximum)));
}

}  // namespace

TouchscreenAxes TouchscreenAxes::forDisplay(cv::Size displaySize, cv::Size2d displaySizeMm) {
    if (displaySize.width <= 0 || displaySize.height <= 0)
        throw InputError("calibration", "display_size",
                         "must be positive to size the virtual touchscreen, found " +
                             std::to_string(displaySize.width) + "x" + std::to_string(displaySize.height));
    if (!std::isfinite(displaySizeMm.width) || !std::isfinite(displaySizeMm.height) ||
        displaySizeMm.width <= 0.0 || displaySizeMm.height <= 0.0)
        throw InputError("calibration", "display_to_projector",
                         "the display does not cover a finite area of the table");
    const double pixelsPerMm =
        std::min(displaySize.width / displaySizeMm.width, displaySize.height / displaySizeMm.height);
    const double unitsPerPixel = std::max(1.0, std::ceil(kMinimumUnitsPerMm / pixelsPerMm));
    if (unitsPerPixel * std::max(displaySize.width, displaySize.height) > kLargestAxisUnits)
        throw InputError("calibration", "display_to_projector",
                         "the display covers an implausibly large area of the table");
    TouchscreenAxes axes;
    axes.unitsPerPixel = static_cast<int>(unitsPerPixel);
    axes.maximumX = displaySize.width * axes.unitsPerPixel - 1;
    axes.maximumY = displaySize.height * axes.unitsPerPixel - 1;
    axes.resolutionX =
        static_cast<int>(std::lround(displaySize.width * axes.unitsPerPixel / displaySizeMm.width));
    axes.resolutionY =
        static_cast<int>(std::lround(displaySize.height * axes.unitsPerPixel / displaySizeMm.height));
    return axes;
}

int TouchscreenAxes::unitsX(double xPx) const {
    return toUnits(xPx, unitsPerPixel, maximumX);
}

int TouchscreenAxes::unitsY(double yPx) const {
    return toUnits(yPx, unitsPerPixel, maximumY);
}

cv::Size2d TouchscreenAxes::sizeMm() const {
    return {static_cast<double>(maximumX) / resolutionX, static_cast<double>(maximumY) / resolutionY};
}

}  // namespace everytouch::io
