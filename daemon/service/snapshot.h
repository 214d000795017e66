#pragma once

#include <optional>
#include <string_view>
#include <vector>

#include <opencv2/core/mat.hpp>

#include "core/calibration.h"
#include "core/contact.h"
#include "core/frame.h"
#include "core/touch_pipeline.h"

namespace everytouch::service {

// What a snapshot shows (the Snapshot method's `what`).
enum class SnapshotKind {
    Camera,       // the newer camera frame of a pair, as the camera gives it
    Texture,      // T = (C+ + C-) / 2: the scene without the code
    Subtraction,  // S = max over channels of (C+ - C-), negative differences clipped to 0: the code
    Mask,         // the hand as the segmentation found it: 255 on the hand
    Overlay,  // the texture in colour with the display's outline, the hand's outline, the fingertips and the
              // contacts (drawOverlay)
};

inline constexpr const char* kSnapshotKinds = "camera, texture, subtraction, mask, overlay";

std::optional<SnapshotKind> parseSnapshotKind(std::string_view name);

// Renders `kind` into `image` (8-bit, the camera's channels; one channel for Subtraction and Mask, BGR for
// Overlay) from what the pipeline made of the pair, so the picture shows what detection used. Without a
// detection result (the pair did not reach the pipeline) the images come from the pair and the mask is empty.
void renderSnapshot(SnapshotKind kind, const core::FramePair& pair, const core::PipelineResult* detection,
                    const std::optional<core::Calibration>& calibration, cv::Mat& image);

// PNG bytes of an 8-bit image.
std::vector<unsigned char> encodePng(const cv::Mat& image);

}  // namespace everytouch::service
