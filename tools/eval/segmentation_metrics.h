#pragma once

#include <cstdint>
#include <optional>

#include <opencv2/core/mat.hpp>

namespace everytouch::eval {

// Paper eq. 23: beta^2 = 0.3 weighs precision more than recall, as in the saliency literature the paper
// follows.
inline constexpr double kBetaSquared = 0.3;

// Pixels of one or many masks compared with the truth. A pixel is hand where the mask is non-zero.
struct PixelCounts {
    std::int64_t truePositive = 0;   // hand in both
    std::int64_t falsePositive = 0;  // hand in the mask only
    std::int64_t falseNegative = 0;  // hand in the truth only

    PixelCounts& operator+=(const PixelCounts& other);

    // p = N_C / N_R; nothing when the mask has no hand pixel.
    std::optional<double> precision() const;
    // r = N_C / N_G; nothing when the truth has no hand pixel.
    std::optional<double> recall() const;
    // Eq. 23; nothing when precision or recall is undefined, 0 when both are 0.
    std::optional<double> fBeta(double betaSquared = kBetaSquared) const;
};

// Compares a method's mask with the truth mask (both CV_8UC1 of one size), over the pixels where `region`
// (CV_8UC1 of that size) is non-zero, or over all pixels when it is empty.
PixelCounts countPixels(const cv::Mat& mask, const cv::Mat& truth, const cv::Mat& region = cv::Mat());

// The scores of one method over many pairs, in two ways:
// - micro average: the pixel counts of all pairs summed, then p, r, F_beta (the paper's N_C, N_R, N_G over
//   its data set); large hands weigh more than small ones;
// - per-pair mean: p, r, F_beta of each pair whose truth has a hand, then averaged. Recall and F_beta are
//   averaged over those pairs (a pair where the method finds nothing scores 0); precision over those of them
//   where the method marked any pixel. Pairs without a hand in the truth enter the micro average only (as
//   false positives).
class SegmentationScore {
public:
    void add(const PixelCounts& pair);

    const PixelCounts& total() const { return total_; }
    int pairs() const { return pairs_; }
    int pairsWithHand() const { return pairsWithHand_; }
    std::optional<double> meanPrecision() const;
    std::optional<double> meanRecall() const;
    std::optional<double> meanFBeta() const;

private:
    PixelCounts total_;
    int pairs_ = 0;
    int pairsWithHand_ = 0;
    int pairsWithPrecision_ = 0;
    double precisionSum_ = 0.0;
    double recallSum_ = 0.0;
    double fBetaSum_ = 0.0;
};

}  // namespace everytouch::eval
