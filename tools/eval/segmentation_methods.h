#pragma once

#include <functional>
#include <optional>
#include <string>
#include <vector>

#include <opencv2/core/mat.hpp>

#include "core/frame.h"
#include "eval/background_subtraction.h"
#include "io/recording.h"

namespace everytouch::eval {

// What a segmentation method sees of one pair (core/code_image.h).
struct SegmentationInput {
    const cv::Mat& texture;      // T = (C+ + C-) / 2, the frames' type
    const cv::Mat& subtraction;  // S = max over channels (C+ - C-), CV_16SC1
    const core::FramePair& pair;
};

// mask: receives CV_8UC1 of the camera's size, 255 where the method sees a hand.
using SegmentFunction = std::function<void(const SegmentationInput& input, cv::Mat& mask)>;

struct SegmentationMethod {
    std::string name;         // short, for the table and the contact sheet
    std::string description;  // what it is and how it was set up for this recording
    SegmentFunction segment;  // empty when unavailable
    // CV_8UC1, the camera's size: nonzero where the method decides hand or not; empty when it decides
    // everywhere. The pipeline's fingertip finder gets it, so fingertips are scored as the pipeline finds
    // them.
    cv::Mat judged;
    std::optional<std::string> unavailable;  // why it cannot run on this recording
};

struct MethodOptions {
    BackgroundOptions background;      // BkSub
    double skinLikelihoodRatio = 1.0;  // SCM, see SkinColourModel

    std::optional<std::string> validate() const;
};

// The methods compared, in the table's order, set up for `recording` from its rig.yml and its frames
// (BkSub's background); nothing else about the rig is used. Throws std::invalid_argument when
// options.validate() fails.
std::vector<SegmentationMethod> segmentationMethods(const io::Recording& recording,
                                                    const MethodOptions& options);

}  // namespace everytouch::eval
