#pragma once

#include <vector>

#include <opencv2/core/mat.hpp>

#include "core/table_code.h"

namespace everytouch::core {

// S and the table's code over a window of blocks.
struct WindowStatistics {
    float correlation = 0.0f;   // of S with the table's code; NaN off the code
    float meanS = 0.0f;         // DN
    float varianceS = 0.0f;     // about its mean, DN^2
    float varianceCode = 0.0f;  // of the predicted code about each block's mean
};

// What the code says about each small block of the camera image, from one subtraction image S: how much
// projector light reaches it and how well S there follows the table's predicted code. Blocks are blockPx
// square; a block's statistics are taken over a window of blocks centred on it, at two sizes: a narrow one
// that follows outlines closely, kept for every block, and a wide one that still sees a faint code, taken
// where it is asked for (the few blocks where the code is faint).
struct CodeEvidence {
    int blockPx = 4;
    int windowBlocks = 3;      // the narrow window's side, blocks (odd)
    int wideWindowBlocks = 5;  // the wide window's side, blocks (odd)

    struct Window {
        cv::Mat
            correlation;    // CV_32FC1, block grid: correlation of S with the table's code; NaN off the code
        cv::Mat meanS;      // CV_32FC1, block grid: mean of S (DN)
        cv::Mat varianceS;  // CV_32FC1, block grid: variance of S about its mean (DN^2)
        cv::Mat varianceCode;  // CV_32FC1, block grid: variance of the predicted code about each block's mean
        int pixels = 0;        // pixels in a whole window
    };
    Window narrow;
    // The wide window centred on one block, and the pixels it holds.
    WindowStatistics wideAt(int by, int bx) const;
    int widePixels() const;

    // Per-block sums, and their integral images, reused from frame to frame.
    cv::Mat blockSums;  // CV_64FC(6): sum S, sum S^2, covariance, variance of S, variance of P, code pixels
    cv::Mat integral;   // CV_64FC(6), one row and column more
    cv::Mat codeSums;   // CV_64FC3: count, sum P, sum P^2 (from the table code, recomputed when it changes)
    const cv::Mat* codeOf = nullptr;  // the predicted code the code sums were taken from
    // Each pixel column's sums of S, S^2 and S P over one row of blocks while they are added up.
    std::vector<int> columnSum;
    std::vector<int> columnSumSquares;
    std::vector<float> columnCross;
};

// subtraction: CV_16SC1 (core/code_image.h), camera size (the last partial blocks are left out).
void measureCodeEvidence(const cv::Mat& subtraction, const TableCode& tableCode, CodeEvidence& evidence);

}  // namespace everytouch::core
