#pragma once

#include <functional>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <opencv2/core/mat.hpp>

#include "eval/fingertip_scoring.h"
#include "eval/segmentation_methods.h"
#include "eval/segmentation_metrics.h"
#include "io/recording.h"

namespace everytouch::eval {

// The fingertips found on a hand mask (CV_8UC1, 255 = hand): their pads, where a touch is reported, raw
// camera pixels. judged: what the method decided (SegmentationMethod::judged; empty: the whole mask), whose
// edge cuts hands as the image's edge does.
using FingertipFinder =
    std::function<void(const cv::Mat& mask, const cv::Mat& judged, std::vector<Eigen::Vector2d>& pads)>;

struct MethodResult {
    std::string name;
    std::string description;
    std::optional<std::string> unavailable;  // not run, and why
    SegmentationScore pixels;                // over the whole frame, as the paper scores
    SegmentationScore displayPixels;         // within the display as the camera sees it (display_region.h)
    FingertipScore fingertips;
    double secondsSegmenting = 0.0;  // in the method's segment(), summed over the pairs
};

struct SegmentationReport {
    std::string recording;
    cv::Size cameraSize;
    int channels = 0;
    int pairs = 0;
    int pairsWithHand = 0;           // pairs whose truth mask has a hand pixel
    int pairsWithHandOnDisplay = 0;  // ... within the display
    bool fingertipTruth = false;     // truth.csv present: fingertips are scored
    double fingerWidthMm = 0.0;
    double fingerWidthPx = 0.0;  // on the table at the display's centre
    std::vector<MethodResult> methods;
    // The fingertip finder on the truth masks: what it reaches when the segmentation is perfect.
    FingertipScore truthMaskFingertips;
    std::vector<std::size_t> handPositions;  // newer frame of each pair whose truth has a hand
};

// Runs every available method on every pair of `recording` (which must have masks) and scores its masks
// against the truth masks, over the whole frame and within the display, and the fingertips found on them
// against truth.csv.
SegmentationReport evaluateSegmentation(const io::Recording& recording, const std::string& recordingName,
                                        const std::vector<SegmentationMethod>& methods,
                                        const FingertipFinder& findFingertips,
                                        const TruthToCamera& truthToCamera, double fingerWidthMm);

}  // namespace everytouch::eval
