#include "eval/segmentation_metrics.h"

#include <gtest/gtest.h>
#include <opencv2/core.hpp>

namespace everytouch::eval {
namespace {

cv::Mat maskWithRect(cv::Rect hand) {
    cv::Mat mask(40, 60, CV_8UC1, cv::Scalar(0));
    mask(hand).setTo(255);
    return mask;
}

TEST(SegmentationMetrics, CountsPixelsOfOverlappingRectangles) {
    // Truth 10x10; the mask covers its right half and 5x10 of background beside it.
    const cv::Mat truth = maskWithRect({10, 10, 10, 10});
    const cv::Mat mask = maskWithRect({15, 10, 10, 10});
    const PixelCounts counts = countPixels(mask, truth);
    EXPECT_EQ(counts.truePositive, 50);
    EXPECT_EQ(counts.falsePositive, 50);
    EXPECT_EQ(counts.falseNegative, 50);
    EXPECT_DOUBLE_EQ(*counts.precision(), 0.5);
    EXPECT_DOUBLE_EQ(*counts.recall(), 0.5);
    EXPECT_DOUBLE_EQ(*counts.fBeta(), 0.5);
}

TEST(SegmentationMetrics, CountsOnlyWithinARegionWhenGivenOne) {
    const cv::Mat truth = maskWithRect({10, 10, 10, 10});
    const cv::Mat mask = maskWithRect({15, 10, 10, 10});
    // The region's left half holds the truth's left half and nothing of the mask.
    const PixelCounts left = countPixels(mask, truth, maskWithRect({0, 0, 15, 40}));
    EXPECT_EQ(left.truePositive, 0);
    EXPECT_EQ(left.falsePositive, 0);
    EXPECT_EQ(left.falseNegative, 50);
    const PixelCounts right = countPixels(mask, truth, maskWithRect({15, 0, 45, 40}));
    EXPECT_EQ(right.truePositive, 50);
    EXPECT_EQ(right.falsePositive, 50);
    EXPECT_EQ(right.falseNegative, 0);
}

TEST(SegmentationMetrics, FBetaFollowsEquation23AndWeighsPrecisionMore) {
    // p = 1/2, r = 1: F = 1.3 * 0.5 / (0.3 * 0.5 + 1).
    const PixelCounts wide{100, 100, 0};
    EXPECT_NEAR(*wide.fBeta(), 1.3 * 0.5 / 1.15, 1e-12);
    // p = 1, r = 1/2 scores higher than the converse.
    const PixelCounts narrow{100, 0, 100};
    EXPECT_NEAR(*narrow.fBeta(), 1.3 * 0.5 / (0.3 + 0.5), 1e-12);
    EXPECT_GT(*narrow.fBeta(), *wide.fBeta());
    // beta^2 = 1 is the harmonic mean.
    EXPECT_NEAR(*wide.fBeta(1.0), 2.0 / 3.0, 1e-12);
}

TEST(SegmentationMetrics, EmptyFramesLeaveTheUndefinedUndefined) {
    const cv::Mat empty = maskWithRect({0, 0, 0, 0});
    const PixelCounts nothing = countPixels(empty, empty);
    EXPECT_FALSE(nothing.precision());
    EXPECT_FALSE(nothing.recall());
    EXPECT_FALSE(nothing.fBeta());
    const PixelCounts spurious = countPixels(maskWithRect({0, 0, 3, 3}), empty);
    EXPECT_DOUBLE_EQ(*spurious.precision(), 0.0);
    EXPECT_FALSE(spurious.recall());
    const PixelCounts missed = countPixels(empty, maskWithRect({0, 0, 3, 3}));
    EXPECT_FALSE(missed.precision());
    EXPECT_DOUBLE_EQ(*missed.recall(), 0.0);
    EXPECT_FALSE(missed.fBeta());
    EXPECT_DOUBLE_EQ(*PixelCounts({0, 5, 5}).fBeta(), 0.0);
}

TEST(SegmentationMetrics, AllHandFrameIsScoredLikeAnyOther) {
    const cv::Mat all(40, 60, CV_8UC1, cv::Scalar(255));
    const PixelCounts counts = countPixels(maskWithRect({0, 0, 30, 40}), all);
    EXPECT_DOUBLE_EQ(*counts.precision(), 1.0);
    EXPECT_DOUBLE_EQ(*counts.recall(), 0.5);
}

TEST(SegmentationScore, MicroAverageWeighsPixelsAndPerPairMeanWeighsPairs) {
    SegmentationScore score;
    score.add({900, 100, 0});  // a large hand, p 0.9, r 1
    score.add({10, 0, 90});    // a small hand, p 1, r 0.1
    score.add({0, 40, 0});     // no hand in the truth: micro average only
    score.add({0, 0, 50});     // a hand the method missed entirely: r 0, no precision
    EXPECT_EQ(score.pairs(), 4);
    EXPECT_EQ(score.pairsWithHand(), 3);
    EXPECT_EQ(score.total().truePositive, 910);
    EXPECT_EQ(score.total().falsePositive, 140);
    EXPECT_EQ(score.total().falseNegative, 140);
    EXPECT_NEAR(*score.total().precision(), 910.0 / 1050.0, 1e-12);
    EXPECT_NEAR(*score.total().recall(), 910.0 / 1050.0, 1e-12);
    EXPECT_NEAR(*score.meanPrecision(), (0.9 + 1.0) / 2, 1e-12);
    EXPECT_NEAR(*score.meanRecall(), (1.0 + 0.1 + 0.0) / 3, 1e-12);
    const double f1 = 1.3 * 0.9 * 1.0 / (0.3 * 0.9 + 1.0), f2 = 1.3 * 1.0 * 0.1 / (0.3 * 1.0 + 0.1);
    EXPECT_NEAR(*score.meanFBeta(), (f1 + f2 + 0.0) / 3, 1e-12);
}

TEST(SegmentationScore, WithoutAnyHandOnlyTheMicroPrecisionIsDefined) {
    SegmentationScore score;
    score.add({0, 12, 0});
    EXPECT_FALSE(score.meanRecall());
    EXPECT_FALSE(score.meanFBeta());
    EXPECT_FALSE(score.total().recall());
    EXPECT_DOUBLE_EQ(*score.total().precision(), 0.0);
}

}  // namespace
}  // namespace everytouch::eval
