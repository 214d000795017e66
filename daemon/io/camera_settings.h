#pragma once

#include <optional>
#include <string>

#include <opencv2/core/types.hpp>

#include "io/camera_pixels.h"

namespace everytouch::io {

// What the configuration asks of a camera ([Camera] keys of everytouchd.conf); unset: the camera's own.
struct CameraSettings {
    std::optional<CameraPixels> pixels;  // PixelFormat=; unset: preferredCameraPixels of what it offers
    std::optional<double> frameRate;     // FrameRate=, frames per second
    std::optional<double> exposureUs;    // ExposureUs=, microseconds
    std::optional<double> gainDb;        // GainDb=, decibels
    std::optional<cv::Rect> region;      // Region=WxH+X+Y, sensor pixels
    // Trigger=: "off" to run free, or the trigger source (e.g. Line0) whose rising edge starts each frame.
    std::optional<std::string> trigger;

    bool operator==(const CameraSettings&) const = default;
};

}  // namespace everytouch::io
