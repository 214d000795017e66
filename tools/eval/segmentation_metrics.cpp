#include "eval/segmentation_metrics.h"

#include <opencv2/core.hpp>

namespace everytouch::eval {

PixelCounts& PixelCounts::operator+=(const PixelCounts& other) {
    truePositive += other.truePositive;
    falsePositive += other.falsePositive;
    falseNegative += other.falseNegative;
    return *this;
}

std::optional<double> PixelCounts::precision() const {
    const std::int64_t marked = truePositive + falsePositive;
    if (marked == 0)
        return std::nullopt;
    return static_cast<double>(truePositive) / static_cast<double>(marked);
}

std::optional<double> PixelCounts::recall() const {
    const std::int64_t hand = truePositive + falseNegative;
    if (hand == 0)
        return std::nullopt;
    return static_cast<double>(truePositive) / static_cast<double>(hand);
}

std::optional<double> PixelCounts::fBeta(double betaSquared) const {
    const std::optional<double> p = precision(), r = recall();
    if (!p || !r)
        return std::nullopt;
    if (*p == 0.0 && *r == 0.0)
        return 0.0;
    return (1.0 + betaSquared) * *p * *r / (betaSquared * *p + *r);
}

PixelCounts countPixels(const cv::Mat& mask, const cv::Mat& truth, const cv::Mat& region) {
    CV_Assert(mask.type() == CV_8UC1 && truth.type() == CV_8UC1 && mask.size() == truth.size());
    CV_Assert(region.empty() || (region.type() == CV_8UC1 && region.size() == mask.size()));
    PixelCounts counts;
    for (int y = 0; y < mask.rows; ++y) {
        const uchar* m = mask.ptr<uchar>(y);
        const uchar* t = truth.ptr<uchar>(y);
        const uchar* r = region.empty() ? nullptr : region.ptr<uchar>(y);
        for (int x = 0; x < mask.cols; ++x) {
            if (r && r[x] == 0)
                continue;
            const bool marked = m[x] != 0, hand = t[x] != 0;
            counts.truePositive += marked && hand;
            counts.falsePositive += marked && !hand;
            counts.falseNegative += !marked && hand;
        }
    }
    return counts;
}

void SegmentationScore::add(const PixelCounts& pair) {
    total_ += pair;
    ++pairs_;
    const std::optional<double> recall = pair.recall();
    if (!recall)
        return;
    ++pairsWithHand_;
    recallSum_ += *recall;
    fBetaSum_ += pair.fBeta().value_or(0.0);
    if (const std::optional<double> precision = pair.precision()) {
        ++pairsWithPrecision_;
        precisionSum_ += *precision;
    }
}

std::optional<double> SegmentationScore::meanPrecision() const {
    if (pairsWithPrecision_ == 0)
        return std::nullopt;
    return precisionSum_ / pairsWithPrecision_;
}

std::optional<double> SegmentationScore::meanRecall() const {
    if (pairsWithHand_ == 0)
        return std::nullopt;
    return recallSum_ / pairsWithHand_;
}

std::optional<double> SegmentationScore::meanFBeta() const {
    if (pairsWithHand_ == 0)
        return std::nullopt;
    return fBetaSum_ / pairsWithHand_;
}

}  // namespace everytouch::eval
