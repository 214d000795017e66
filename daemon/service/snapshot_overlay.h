#pragma once

#include <optional>

#include <opencv2/core/mat.hpp>

#include "core/calibration.h"
#include "core/contact.h"
#include "core/touch_pipeline.h"

namespace everytouch::service {

// Draws onto `image` (8-bit BGR, raw camera pixels) what the daemon believes about the scene, so a person can
// check it against what the camera sees: the outline of the projected display on the table, and every contact
// where it is, at its height (a filled dot when touching, a ring when hovering, gray for a palm), labelled
// with its id and height in mm. Without a calibration there is nowhere to draw them; the image says so.
void drawOverlay(const std::optional<core::Calibration>& calibration, const core::Contacts& contacts,
                 cv::Mat& image);

// Draws what detection found in the camera image: the hand's outline (blue) and each fingertip (a cross at
// its end, a line along the finger).
void drawDetection(const core::PipelineResult& detection, cv::Mat& image);

}  // namespace everytouch::service
