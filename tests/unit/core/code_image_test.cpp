#include "core/code_image.h"

#include <algorithm>
#include <cmath>

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <opencv2/core.hpp>

namespace everytouch::core {
namespace {

using ::testing::HasSubstr;
using ::testing::Optional;

// 67 pixels wide: whole vectors of every width and a remainder.
constexpr int kWidth = 67;

FramePair randomPair(int type, int seed) {
    cv::RNG rng(seed);
    FramePair pair;
    pair.positive.image.create(48, kWidth, type);
    pair.negative.image.create(48, kWidth, type);
    rng.fill(pair.positive.image, cv::RNG::UNIFORM, 0, 256);
    rng.fill(pair.negative.image, cv::RNG::UNIFORM, 0, 256);
    pair.negative.polarity = Polarity::Negative;
    return pair;
}

TEST(SubtractionAndTexture, GrayFramesGiveTheirDifferenceAndRoundedMean) {
    const FramePair pair = randomPair(CV_8UC1, 1);
    cv::Mat subtraction, texture;
    computeSubtractionAndTexture(pair, subtraction, texture);
    ASSERT_EQ(subtraction.type(), CV_16SC1);
    ASSERT_EQ(texture.type(), CV_8UC1);
    for (int y = 0; y < 48; ++y)
        for (int x = 0; x < kWidth; ++x) {
            const int plus = pair.positive.image.at<uchar>(y, x);
            const int minus = pair.negative.image.at<uchar>(y, x);
            ASSERT_EQ(subtraction.at<short>(y, x), plus - minus);
            ASSERT_EQ(texture.at<uchar>(y, x), (plus + minus + 1) / 2);
        }
}

TEST(SubtractionAndTexture, ColourFramesGiveTheLargestChannelDifferenceAndThePerChannelMean) {
    const FramePair pair = randomPair(CV_8UC3, 2);
    cv::Mat subtraction, texture;
    computeSubtractionAndTexture(pair, subtraction, texture);
    ASSERT_EQ(texture.type(), CV_8UC3);
    for (int y = 0; y < 48; ++y)
        for (int x = 0; x < kWidth; ++x) {
            const cv::Vec3b plus = pair.positive.image.at<cv::Vec3b>(y, x);
            const cv::Vec3b minus = pair.negative.image.at<cv::Vec3b>(y, x);
            int largest = -256;
            for (int c = 0; c < 3; ++c) {
                largest = std::max(largest, plus[c] - minus[c]);
                ASSERT_EQ(texture.at<cv::Vec3b>(y, x)[c], (plus[c] + minus[c] + 1) / 2);
            }
            ASSERT_EQ(subtraction.at<short>(y, x), largest);
        }
}

TEST(SubtractionAndTexture, OutputsAreReusedFromFrameToFrame) {
    cv::Mat subtraction, texture, localMean, codeImage;
    computeSubtractionAndTexture(randomPair(CV_8UC3, 3), subtraction, texture);
    binarizeSubtraction(subtraction, 3, {}, localMean, codeImage);
    const uchar* buffers[] = {subtraction.data, texture.data, localMean.data, codeImage.data};
    computeSubtractionAndTexture(randomPair(CV_8UC3, 4), subtraction, texture);
    binarizeSubtraction(subtraction, 3, {}, localMean, codeImage);
    EXPECT_EQ(subtraction.data, buffers[0]);
    EXPECT_EQ(texture.data, buffers[1]);
    EXPECT_EQ(localMean.data, buffers[2]);
    EXPECT_EQ(codeImage.data, buffers[3]);
}

TEST(BinarizationOptions, ValidateNamesTheFieldAtFault) {
    EXPECT_EQ(BinarizationOptions{}.validate(), std::nullopt);
    BinarizationOptions options;
    options.neighbourhood = 8;
    EXPECT_THAT(options.validate(), Optional(HasSubstr("neighbourhood")));
    options = {};
    options.noiseSigmaDn = -1;
    EXPECT_THAT(options.validate(), Optional(HasSubstr("noiseSigmaDn")));
    options = {};
    options.maxErrorProbability = 0;
    EXPECT_THAT(options.validate(), Optional(HasSubstr("maxErrorProbability")));
    options = {};
    options.mixtureMargin = 0.5;
    EXPECT_THAT(options.validate(), Optional(HasSubstr("mixtureMargin")));
    cv::Mat localMean, codeImage;
    EXPECT_THROW(
        binarizeSubtraction(cv::Mat(8, 8, CV_16SC1, cv::Scalar(0)), 1, options, localMean, codeImage),
        std::invalid_argument);
}

// S of a gray camera whose pixels each see one code bit: amplitude * bit + the difference of two frames'
// noise.
struct SyntheticSubtraction {
    cv::Mat bits;  // CV_8UC1, 0/1
    cv::Mat subtraction;
};

SyntheticSubtraction subtractionOf(const cv::Mat& amplitude, double noiseSigmaDn, int seed) {
    cv::RNG rng(seed);
    SyntheticSubtraction s;
    s.bits.create(amplitude.size(), CV_8UC1);
    rng.fill(s.bits, cv::RNG::UNIFORM, 0, 2);
    cv::Mat noise(amplitude.size(), CV_32FC1);
    rng.fill(noise, cv::RNG::NORMAL, 0.0, noiseSigmaDn * std::sqrt(2.0));
    cv::Mat bitsF;
    s.bits.convertTo(bitsF, CV_32F);
    cv::Mat value = amplitude.mul(bitsF) + noise;
    value.convertTo(s.subtraction, CV_16S);
    return s;
}

struct BitCounts {
    double errorRate;    // among known pixels
    double unknownRate;  // among all pixels
};

BitCounts countBits(const cv::Mat& codeImage, const cv::Mat& bits, const cv::Rect& region) {
    double known = 0, wrong = 0;
    for (int y = region.y; y < region.br().y; ++y)
        for (int x = region.x; x < region.br().x; ++x) {
            const uchar seen = codeImage.at<uchar>(y, x);
            if (seen == kUnknownBit)
                continue;
            known += 1;
            wrong += seen != bits.at<uchar>(y, x);
        }
    return {known > 0 ? wrong / known : 0.0, 1.0 - known / region.area()};
}

// The amplitude of the code follows the surface's albedo: a bright surface gives 2 delta gain albedo = 24 DN,
// a dark stain 6 DN. One global threshold cannot serve both; the local mean does.
TEST(Binarization, ReadsTheCodeOnBrightAndDarkSurfaceAlike) {
    cv::Mat amplitude(120, 160, CV_32FC1, cv::Scalar(24));
    amplitude.colRange(80, 160).setTo(6);
    const double noise = 1.0;
    const SyntheticSubtraction s = subtractionOf(amplitude, noise, 1);
    BinarizationOptions options;
    options.noiseSigmaDn = noise;
    cv::Mat localMean, codeImage;
    binarizeSubtraction(s.subtraction, 1, options, localMean, codeImage);

    // Away from the albedo edge, where the neighbourhood straddles both surfaces.
    const BitCounts bright = countBits(codeImage, s.bits, {0, 0, 70, 120});
    const BitCounts dark = countBits(codeImage, s.bits, {90, 0, 70, 120});
    EXPECT_LT(bright.errorRate, 0.001);
    EXPECT_LT(bright.unknownRate, 0.01);
    // 6 DN over a difference noise of 1.45 DN: each level 2 sigma from the threshold.
    EXPECT_LT(dark.errorRate, 0.05);
    EXPECT_LT(dark.unknownRate, 0.5);

    // The best single threshold for the bright surface loses the dark one.
    cv::Mat global = s.subtraction > 12;
    global /= 255;
    cv::Mat wrong = global(cv::Rect(90, 0, 70, 120)) != s.bits(cv::Rect(90, 0, 70, 120));
    EXPECT_GT(cv::countNonZero(wrong), 0.4 * 70 * 120);
}

TEST(Binarization, WhereNoCodeArrivesEveryBitIsUnknownNotZero) {
    // A colour camera on a shadow: S is the largest of three noise differences, biased above zero.
    const double noise = 2.0;
    cv::RNG rng(2);
    cv::Mat channels[3];
    for (cv::Mat& channel : channels) {
        channel.create(100, 100, CV_32FC1);
        rng.fill(channel, cv::RNG::NORMAL, 0.0, noise * std::sqrt(2.0));
    }
    cv::Mat largest = cv::max(cv::max(channels[0], channels[1]), channels[2]);
    cv::Mat subtraction;
    largest.convertTo(subtraction, CV_16S);
    BinarizationOptions options;
    options.noiseSigmaDn = noise;
    cv::Mat localMean, codeImage;
    binarizeSubtraction(subtraction, 3, options, localMean, codeImage);
    EXPECT_GT(cv::countNonZero(codeImage == kUnknownBit), 0.99 * 100 * 100);
}

TEST(Binarization, AStrongNegativeDifferenceIsMotionNotAZeroBit) {
    cv::Mat amplitude(60, 60, CV_32FC1, cv::Scalar(30));
    SyntheticSubtraction s = subtractionOf(amplitude, 1.0, 3);
    s.subtraction(cv::Rect(30, 30, 4, 4)).setTo(-40);  // an edge that moved between the frames
    BinarizationOptions options;
    options.noiseSigmaDn = 1.0;
    cv::Mat localMean, codeImage;
    binarizeSubtraction(s.subtraction, 1, options, localMean, codeImage);
    EXPECT_EQ(cv::countNonZero(codeImage(cv::Rect(30, 30, 4, 4)) == kUnknownBit), 16);
}

TEST(Binarization, PixelsMixingBothBitsAreUnknown) {
    // A checkerboard of bits, amplitude 40 DN, no noise.
    cv::Mat bits(60, 60, CV_8UC1);
    for (int y = 0; y < bits.rows; ++y)
        for (int x = 0; x < bits.cols; ++x)
            bits.at<uchar>(y, x) = (x + y) % 2;
    cv::Mat subtraction;
    bits.convertTo(subtraction, CV_16S, 40.0);
    // Camera pixels straddling a 1-bit and a 0-bit half and half.
    subtraction(cv::Rect(20, 20, 3, 3)).setTo(20);
    cv::Mat localMean, codeImage;
    BinarizationOptions options;
    options.noiseSigmaDn = 0.0;
    binarizeSubtraction(subtraction, 1, options, localMean, codeImage);
    EXPECT_EQ(cv::countNonZero(codeImage(cv::Rect(20, 20, 3, 3)) == kUnknownBit), 9);
    const BitCounts elsewhere = countBits(codeImage, bits, {30, 30, 20, 20});
    EXPECT_EQ(elsewhere.unknownRate, 0.0);
    EXPECT_EQ(elsewhere.errorRate, 0.0);
}

}  // namespace
}  // namespace everytouch::core
