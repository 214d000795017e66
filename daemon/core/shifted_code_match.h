#pragma once

#include <vector>

#include <opencv2/core/mat.hpp>

namespace everytouch::core {

// How well a region of S follows the table's predicted code when that code is allowed to lie a little off
// where the calibration puts it: the best correlation over shifts within a radius, at half-pixel steps. A
// table whose calibration is slightly off (a camera knocked by a fraction of a degree, a projector whose
// image crept) shows its own code, sharp and at full strength, beside the predicted place; something above
// the table shows it displaced by parallax (1 mm of height moves it some 0.2 projector pixels on a common
// rig) and, on skin, blurred.
struct CodeShiftMatch {
    float correlation = 0.0f;  // the best; 0 without samples
    // S at a pixel p follows the prediction at p + shift (camera pixels): the code lies -shift from where
    // the prediction puts it.
    float shiftX = 0.0f, shiftY = 0.0f;
};

class ShiftedCodeMatcher {
public:
    // predicted: the table's code (core/table_code.h), CV_32FC1, camera size. Prepares the code at the
    // three half-pixel phases; computed once per calibration.
    void setCode(const cv::Mat& predicted);
    bool hasCode() const { return !phases_[0][0].empty(); }

    // subtraction: S, CV_16SC1, camera size. blocks: the top-left corners of the region's blocks, each
    // blockPx square and inside the image. The correlation is pooled over the blocks about each block's own
    // means (as core/code_evidence.h takes it), so that content and albedo changing from block to block do
    // not lower it. The shifts are sought on a whole-pixel grid within radiusPx, then refined to half a pixel
    // around the best. Allocates nothing.
    CodeShiftMatch bestMatch(const cv::Mat& subtraction, const std::vector<cv::Point>& blocks, int blockPx,
                             double radiusPx) const;

private:
    // The pooled correlation with the code shifted by (halfStepsX, halfStepsY) half pixels.
    float correlationAt(const cv::Mat& subtraction, const std::vector<cv::Point>& blocks, int blockPx,
                        int halfStepsX, int halfStepsY) const;

    // phases_[fy][fx]: the code sampled half a pixel further right (fx) and down (fy), by linear
    // interpolation; the last row and column repeat.
    cv::Mat phases_[2][2];
};

}  // namespace everytouch::core
