#pragma once

#include <opencv2/core/mat.hpp>

#include "core/table_code.h"

namespace everytouch::core {

// What the code says about each small block of the camera image, from one subtraction image S: whether the
// projector's light reaches it and whether the code there is the table's. Blocks are blockPx square; the
// statistics of a block are taken over the window of windowBlocks x windowBlocks blocks centred on it.
struct CodeEvidence {
    int blockPx = 4;
    int windowBlocks = 3;
    cv::Mat
        correlation;    // CV_32FC1, block grid: correlation of S with the table's predicted code; NaN outside
    cv::Mat meanS;      // CV_32FC1, block grid: mean of S (DN)
    cv::Mat varianceS;  // CV_32FC1, block grid: variance of S about its mean (DN^2)
    cv::Mat varianceCode;  // CV_32FC1, block grid: variance of the predicted code about each block's mean
    // Per-block sums over the frame, reused from frame to frame.
    cv::Mat sums;      // CV_64FC3: sum S, sum S^2, sum S*P
    cv::Mat codeSums;  // CV_64FC3: count, sum P, sum P^2 (from the table code, recomputed when it changes)
    const cv::Mat* codeOf = nullptr;  // the predicted code the code sums were taken from
};

// subtraction: CV_16SC1 (core/code_image.h), camera size, a multiple of blockPx or not (the last partial
// blocks are left out).
void measureCodeEvidence(const cv::Mat& subtraction, const TableCode& tableCode, CodeEvidence& evidence);

}  // namespace everytouch::core
