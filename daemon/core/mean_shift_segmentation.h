#pragma once

#include <optional>
#include <string>
#include <vector>

#include <opencv2/core/mat.hpp>

namespace everytouch::core {

// Mean-shift smoothing and segmentation (Comaniciu and Meer; paper section VI.A.2) with the paper's
// (hs, hr, M) = (7, 10, 20): colours are smoothed by mean shift in the joint space of position (window
// radius hs pixels) and colour (radius hr levels), neighbouring pixels whose smoothed colours lie within hr
// form one region, and regions smaller than M pixels join the neighbour of the nearest colour.
struct MeanShiftOptions {
    int spatialRadius = 7;     // hs, pixels
    double colourRadius = 10;  // hr, colour levels
    int minRegionPixels = 20;  // M, pixels

    std::optional<std::string> validate() const;
};

struct MeanShiftScratch {
    cv::Mat filtered;
    std::vector<int> parent;
    std::vector<int> size;
    std::vector<cv::Vec3f> colourSum;
    std::vector<int> compact;
};

// image: CV_8UC3. labels: CV_32SC1 of the image's size, regions numbered 0 .. count-1. Returns the count.
int segmentMeanShift(const cv::Mat& image, const MeanShiftOptions& options, MeanShiftScratch& scratch,
                     cv::Mat& labels);

}  // namespace everytouch::core
