#include "core/pattern.h"

#include <algorithm>
#include <bit>
#include <chrono>
#include <cstdio>

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <opencv2/core.hpp>

#include "support/synthetic_capture.h"

namespace everytouch::core {
namespace {

using ::testing::HasSubstr;
using ::testing::Optional;

TEST(PatternOptions, DefaultsAreValid) {
    EXPECT_EQ(PatternOptions{}.validate(), std::nullopt);
}

TEST(PatternOptions, ValidateNamesTheFieldAtFault) {
    PatternOptions options;
    options.window = 9;
    EXPECT_THAT(options.validate(), Optional(HasSubstr("window")));
    options = {};
    options.window = 4;  // 16 bits for 301 625 windows
    EXPECT_THAT(options.validate(), Optional(HasSubstr("cannot label")));
    options = {};
    options.size = {5, 480};
    EXPECT_THAT(options.validate(), Optional(HasSubstr("size")));
    options = {};
    options.minDistance = 7;
    EXPECT_THAT(options.validate(), Optional(HasSubstr("minDistance")));
    options = {};
    options.neighbourRadius = 6;
    EXPECT_THAT(options.validate(), Optional(HasSubstr("neighbourRadius")));
    options = {};
    options.repairTrialsPerWindow = -1;
    EXPECT_THAT(options.validate(), Optional(HasSubstr("repairTrialsPerWindow")));
    EXPECT_THROW(generatePattern(options), std::invalid_argument);
}

TEST(Pattern, IsBinaryOfTheRequestedSizeAndDeterminedByTheSeed) {
    PatternOptions options;
    options.size = {160, 120};
    const cv::Mat first = generatePattern(options);
    ASSERT_EQ(first.type(), CV_8UC1);
    ASSERT_EQ(first.size(), options.size);
    double lowest, highest;
    cv::minMaxLoc(first, &lowest, &highest);
    EXPECT_EQ(lowest, 0.0);
    EXPECT_EQ(highest, 1.0);
    EXPECT_NEAR(cv::mean(first)[0], 0.5, 0.02);
    EXPECT_EQ(cv::countNonZero(first != generatePattern(options)), 0);
    options.seed = 2;
    EXPECT_GT(cv::countNonZero(first != generatePattern(options)), first.total() / 3);
}

TEST(Pattern, CodewordBitsRunRowByRowFromTheTopLeftToTheAnchor) {
    cv::Mat pattern = cv::Mat::zeros(20, 30, CV_8UC1);
    pattern.at<uchar>(7, 10) = 1;                                    // row 7, column 10
    EXPECT_EQ(codeAt(pattern, {10, 7}, 6), std::uint64_t{1} << 35);  // the anchor is the last bit
    EXPECT_EQ(codeAt(pattern, {15, 12}, 6), std::uint64_t{1});       // the top-left is the first
    EXPECT_EQ(codeAt(pattern, {12, 9}, 6), std::uint64_t{1} << (3 * 6 + 3));
    EXPECT_EQ(codeAt(pattern, {16, 7}, 6), 0u);
    EXPECT_EQ(codedRegion(pattern.size(), 6), cv::Rect(5, 5, 25, 15));
}

TEST(Pattern, WindowCodesAreTheCodewordsOfEveryAnchorRowByRow) {
    cv::Mat pattern(37, 53, CV_8UC1);
    cv::randu(pattern, 0, 2);
    for (int window : {2, 5, 6, 8}) {
        const std::vector<std::uint64_t> codes = windowCodes(pattern, window);
        const cv::Rect anchors = codedRegion(pattern.size(), window);
        ASSERT_EQ(codes.size(), anchors.area());
        std::size_t i = 0;
        for (int y = anchors.y; y < anchors.br().y; ++y)
            for (int x = anchors.x; x < anchors.br().x; ++x, ++i)
                ASSERT_EQ(codes[i], codeAt(pattern, {x, y}, window)) << window << " at " << x << "," << y;
    }
}

// Brute force over every pair, as the analysis' definition says.
TEST(Pattern, AnalysisAgreesWithAnExhaustiveComparisonOfAllWindows) {
    cv::Mat pattern(60, 50, CV_8UC1);
    cv::randu(pattern, 0, 2);
    pattern(cv::Rect(20, 20, 9, 9)).setTo(0);  // a blank patch repeats codewords
    const int window = 5;
    const int neighbourRadius = 1;
    const PatternAnalysis analysis = analyzePattern(pattern, window, neighbourRadius, 200);

    const cv::Rect anchors = codedRegion(pattern.size(), window);
    std::vector<cv::Point> points;
    std::vector<std::uint64_t> codes;
    for (int y = anchors.y; y < anchors.br().y; ++y)
        for (int x = anchors.x; x < anchors.br().x; ++x) {
            points.emplace_back(x, y);
            codes.push_back(codeAt(pattern, {x, y}, window));
        }
    std::vector<std::size_t> closePairs(analysis.closePairs.size(), 0);
    std::vector<bool> repeated(codes.size(), false);
    int minDistance = 64;
    for (std::size_t a = 0; a < codes.size(); ++a)
        for (std::size_t b = a + 1; b < codes.size(); ++b) {
            const int distance = std::popcount(codes[a] ^ codes[b]);
            if (distance == 0)
                repeated[a] = repeated[b] = true;
            const cv::Point gap = points[a] - points[b];
            if (distance > 0 && std::max(std::abs(gap.x), std::abs(gap.y)) <= neighbourRadius)
                continue;
            minDistance = std::min(minDistance, distance);
            if (distance < static_cast<int>(closePairs.size()))
                ++closePairs[distance];
        }
    EXPECT_EQ(analysis.windowCount, codes.size());
    EXPECT_EQ(analysis.repeatedWindows,
              static_cast<std::size_t>(std::count(repeated.begin(), repeated.end(), true)));
    EXPECT_GT(analysis.repeatedWindows, 0u);
    EXPECT_FALSE(analysis.unique());
    EXPECT_EQ(analysis.minDistance, 0);
    EXPECT_EQ(minDistance, 0);
    EXPECT_EQ(analysis.closePairs, closePairs);
    EXPECT_NEAR(analysis.meanDistance, 12.5, 1.0);  // 25 random bits
    EXPECT_EQ(analysis.samples, 200);
}

TEST(Pattern, AnalysisFindsMinimumDistancesBeyondTheCloseRangeExhaustively) {
    PatternOptions options;
    options.size = {40, 30};
    options.minDistance = 6;
    const cv::Mat pattern = generatePattern(options);
    const PatternAnalysis analysis = analyzePattern(pattern, options.window, options.neighbourRadius, 100);
    EXPECT_TRUE(analysis.unique());
    EXPECT_GE(analysis.minDistance, 6);
    for (std::size_t d = 0; d < 6; ++d)
        EXPECT_EQ(analysis.closePairs[d], 0u) << d;
}

// The paper's approach (plain random) against the repair pass, on the default 640x480 panel with 6x6 windows.
TEST(Pattern, DefaultPatternHasUniqueWindowsAndAHigherMinimumDistanceThanPlainRandom) {
    const cv::Mat& repaired = test::defaultPattern();
    // Uniqueness by sorting every window's codeword, read pixel by pixel.
    const cv::Rect anchors = codedRegion(repaired.size(), 6);
    std::vector<std::uint64_t> codes;
    for (int y = anchors.y; y < anchors.br().y; ++y)
        for (int x = anchors.x; x < anchors.br().x; ++x)
            codes.push_back(codeAt(repaired, {x, y}, 6));
    std::sort(codes.begin(), codes.end());
    EXPECT_EQ(std::adjacent_find(codes.begin(), codes.end()), codes.end());
    EXPECT_EQ(codes.size(), 635u * 475u);

    PatternOptions plainOptions;
    plainOptions.minDistance = 0;
    const cv::Mat plain = generatePattern(plainOptions);
    const int samples = 300;
    const PatternAnalysis before = analyzePattern(plain, 6, plainOptions.neighbourRadius, samples);
    const PatternAnalysis after = analyzePattern(repaired, 6, PatternOptions{}.neighbourRadius, samples);
    std::printf("plain random: unique %d, min %d, mean %.3f, mean nearest %.3f, pairs at 0..5:",
                before.unique(), before.minDistance, before.meanDistance, before.meanNearestDistance);
    for (std::size_t pairs : before.closePairs)
        std::printf(" %zu", pairs);
    std::printf("\nrepaired:     unique %d, min %d, mean %.3f, mean nearest %.3f, pairs at 0..5:",
                after.unique(), after.minDistance, after.meanDistance, after.meanNearestDistance);
    for (std::size_t pairs : after.closePairs)
        std::printf(" %zu", pairs);
    std::printf("\n");
    EXPECT_TRUE(after.unique());
    EXPECT_GE(after.minDistance, 4);
    EXPECT_GT(after.minDistance, before.minDistance);
    EXPECT_LE(before.minDistance, 2);  // about 25 pairs at distance <= 1 are expected by chance
    // The repair flips few bits: the pattern stays as random as before.
    EXPECT_NEAR(after.meanDistance, 18.0, 0.5);
    EXPECT_GE(after.meanNearestDistance, before.meanNearestDistance - 0.15);
    EXPECT_LT(cv::countNonZero(plain != repaired), static_cast<int>(plain.total() / 50));
}

}  // namespace
}  // namespace everytouch::core
