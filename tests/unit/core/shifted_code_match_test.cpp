#include "core/shifted_code_match.h"

#include <cmath>
#include <random>
#include <vector>

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

namespace everytouch::core {
namespace {

// A code of random bits 2 px wide, blurred as a camera blurs it, and S showing it moved by (dx, dy) pixels
// at `gain` DN a bit, with noise of `noiseSd` DN.
struct ShiftedScene {
    cv::Mat code, subtraction;
};

ShiftedScene makeScene(double dx, double dy, double gain, double noiseSd, unsigned seed) {
    const cv::Size size(160, 120);
    std::mt19937 random(seed);
    std::bernoulli_distribution bit(0.5);
    cv::Mat bits(size.height / 2, size.width / 2, CV_32FC1);
    for (int y = 0; y < bits.rows; ++y)
        for (int x = 0; x < bits.cols; ++x)
            bits.at<float>(y, x) = bit(random) ? 1.0f : 0.0f;
    cv::Mat code;
    cv::resize(bits, code, size, 0, 0, cv::INTER_NEAREST);
    cv::GaussianBlur(code, code, cv::Size(0, 0), 0.8);
    // S at p shows the code at p - shift: the code lies `shift` from where the prediction puts it.
    cv::Mat moved;
    const cv::Mat translation = (cv::Mat_<double>(2, 3) << 1, 0, dx, 0, 1, dy);
    cv::warpAffine(code, moved, translation, size, cv::INTER_LINEAR, cv::BORDER_REFLECT);
    cv::Mat noise(size, CV_32FC1);
    cv::randn(noise, 0.0, noiseSd);
    cv::Mat subtraction;
    cv::Mat(moved * gain + noise).convertTo(subtraction, CV_16SC1);
    return {code, subtraction};
}

std::vector<cv::Point> blocksIn(const cv::Rect& region, int blockPx) {
    std::vector<cv::Point> blocks;
    for (int y = region.y; y + blockPx <= region.y + region.height; y += blockPx)
        for (int x = region.x; x + blockPx <= region.x + region.width; x += blockPx)
            blocks.emplace_back(x, y);
    return blocks;
}

TEST(ShiftedCodeMatch, FindsWhereTheCodeLiesToHalfAPixel) {
    const ShiftedScene scene = makeScene(1.5, -1.0, 20.0, 2.0, 1);
    ShiftedCodeMatcher matcher;
    matcher.setCode(scene.code);
    const std::vector<cv::Point> blocks = blocksIn(cv::Rect(40, 30, 48, 48), 4);

    const CodeShiftMatch match = matcher.bestMatch(scene.subtraction, blocks, 4, 2.5);
    // S at p follows the code the prediction puts at p + shift.
    EXPECT_FLOAT_EQ(match.shiftX, -1.5f);
    EXPECT_FLOAT_EQ(match.shiftY, 1.0f);
    EXPECT_GT(match.correlation, 0.9f);

    // Sought within half a pixel, the code 1.8 px off is not found.
    const CodeShiftMatch near = matcher.bestMatch(scene.subtraction, blocks, 4, 0.5);
    EXPECT_LT(near.correlation, 0.5f);
}

TEST(ShiftedCodeMatch, ACodeInItsPlaceIsFoundThereAndNoiseNowhere) {
    const ShiftedScene inPlace = makeScene(0.0, 0.0, 20.0, 2.0, 2);
    ShiftedCodeMatcher matcher;
    matcher.setCode(inPlace.code);
    const std::vector<cv::Point> blocks = blocksIn(cv::Rect(40, 30, 48, 48), 4);
    const CodeShiftMatch match = matcher.bestMatch(inPlace.subtraction, blocks, 4, 2.0);
    EXPECT_EQ(match.shiftX, 0.0f);
    EXPECT_EQ(match.shiftY, 0.0f);
    EXPECT_GT(match.correlation, 0.9f);

    // Another code (something above the table shows one moved by parallax beyond the reach) or noise alone:
    // chance, over 2 300 pixels and the shifts tried, stays far below.
    const ShiftedScene other = makeScene(0.0, 0.0, 20.0, 2.0, 3);
    EXPECT_LT(matcher.bestMatch(other.subtraction, blocks, 4, 2.0).correlation, 0.2f);
    const ShiftedScene noise = makeScene(0.0, 0.0, 0.0, 5.0, 4);
    EXPECT_LT(matcher.bestMatch(noise.subtraction, blocks, 4, 2.0).correlation, 0.2f);
}

TEST(ShiftedCodeMatch, ContentChangingFromBlockToBlockDoesNotLowerIt) {
    // Each block's own means are taken out: a brightness that steps between blocks (print, content) is
    // not code.
    ShiftedScene scene = makeScene(0.5, 0.5, 20.0, 1.0, 5);
    for (int y = 0; y < scene.subtraction.rows; ++y)
        for (int x = 0; x < scene.subtraction.cols; ++x)
            scene.subtraction.at<short>(y, x) += static_cast<short>(((x / 4 + y / 4) % 2) * 60);
    ShiftedCodeMatcher matcher;
    matcher.setCode(scene.code);
    const CodeShiftMatch match =
        matcher.bestMatch(scene.subtraction, blocksIn(cv::Rect(40, 32, 48, 48), 4), 4, 2.0);
    EXPECT_GT(match.correlation, 0.9f);
    EXPECT_FLOAT_EQ(match.shiftX, -0.5f);
    EXPECT_FLOAT_EQ(match.shiftY, -0.5f);
}

}  // namespace
}  // namespace everytouch::core
