#include "eval/background_subtraction.h"

#include <cmath>
#include <stdexcept>

#include <gtest/gtest.h>
#include <opencv2/core.hpp>

namespace everytouch::eval {
namespace {

constexpr int kWidth = 256, kHeight = 160;

// Noise variance of a sensor with read noise and shot noise, DN^2 at a level.
double noiseVariance(double level) {
    return 0.3 + 0.02 * level;
}

// A still scene: a level ramp across, the three channels at different fractions of it.
cv::Mat scene() {
    cv::Mat image(kHeight, kWidth, CV_32FC3);
    for (int y = 0; y < kHeight; ++y)
        for (int x = 0; x < kWidth; ++x) {
            const float level = 12.0f + 0.9f * x;
            image.at<cv::Vec3f>(y, x) = {level * 0.8f, level, level * 0.9f};
        }
    return image;
}

// One texture of `truth` with the sensor's noise, rounded to 8 bits.
cv::Mat expose(const cv::Mat& truth, cv::RNG& rng) {
    cv::Mat image(truth.size(), CV_8UC3);
    for (int y = 0; y < truth.rows; ++y)
        for (int x = 0; x < truth.cols; ++x)
            for (int c = 0; c < 3; ++c) {
                const double level = truth.at<cv::Vec3f>(y, x)[c];
                image.at<cv::Vec3b>(y, x)[c] =
                    cv::saturate_cast<uchar>(level + rng.gaussian(std::sqrt(noiseVariance(level))));
            }
    return image;
}

cv::Mat withHand(const cv::Mat& truth, cv::Rect hand) {
    cv::Mat image = truth.clone();
    image(hand).setTo(cv::Scalar(90, 140, 200));
    return image;
}

TEST(TextureNoise, MeasuresTheSensorsNoiseAtEachLevel) {
    cv::RNG rng(3);
    const cv::Mat still = scene();
    std::vector<cv::Mat> textures;
    for (int i = 0; i < 15; ++i)
        textures.push_back(expose(still, rng));
    for (int channel = 0; channel < 3; ++channel) {
        const NoiseTable sigma = estimateTextureNoise(textures, channel, channel % 4);
        for (int level : {30, 80, 128, 180}) {
            // The 8-bit rounding adds 1/12 DN^2.
            const double expected = std::sqrt(noiseVariance(level) + 1.0 / 12.0);
            EXPECT_NEAR(sigma[level], expected, 0.05 * expected)
                << "channel " << channel << ", level " << level;
        }
    }
}

TEST(TextureNoise, EachChannelHasItsOwn) {
    // Colour gains make the channels of one level differ in noise: here sigma 1, 2 and 3 DN at level 100.
    cv::RNG rng(8);
    std::vector<cv::Mat> textures;
    for (int i = 0; i < 15; ++i) {
        cv::Mat image(kHeight, kWidth, CV_8UC3);
        for (int y = 0; y < kHeight; ++y)
            for (int x = 0; x < kWidth; ++x)
                for (int c = 0; c < 3; ++c)
                    image.at<cv::Vec3b>(y, x)[c] = cv::saturate_cast<uchar>(100.0 + rng.gaussian(c + 1.0));
        textures.push_back(image);
    }
    for (int c = 0; c < 3; ++c) {
        const double expected = std::sqrt((c + 1.0) * (c + 1.0) + 1.0 / 12.0);
        EXPECT_NEAR(estimateTextureNoise(textures, c, 0)[100], expected, 0.05 * expected) << "channel " << c;
    }
}

TEST(TextureNoise, TellsTheMosaicsPlacesAndTheBorderApart) {
    // Like a demosaiced colour camera: the measured place of a 2x2 cell noisier than the interpolated ones,
    // the border noisier still. Pooled, these would make a heavy-tailed mixture.
    auto sigmaOf = [](int x, int y) {
        if (x == 0 || y == 0 || x == kWidth - 1 || y == kHeight - 1)
            return 3.0;
        return x % 2 == 0 && y % 2 == 0 ? 2.0 : 0.8;
    };
    cv::RNG rng(9);
    auto exposeMosaic = [&](const cv::Mat& truth) {
        cv::Mat image(truth.size(), CV_8UC1);
        for (int y = 0; y < truth.rows; ++y)
            for (int x = 0; x < truth.cols; ++x)
                image.at<uchar>(y, x) =
                    cv::saturate_cast<uchar>(truth.at<float>(y, x) + rng.gaussian(sigmaOf(x, y)));
        return image;
    };
    const cv::Mat still(kHeight, kWidth, CV_32FC1, cv::Scalar(120));
    std::vector<cv::Mat> samples;
    for (int i = 0; i < 15; ++i)
        samples.push_back(exposeMosaic(still));
    for (int pixelClass = 0; pixelClass < kNoiseClasses; ++pixelClass) {
        const double sigma = pixelClass == 4 ? 3.0 : pixelClass == 0 ? 2.0 : 0.8;
        const double expected = std::sqrt(sigma * sigma + 1.0 / 12.0);
        EXPECT_NEAR(estimateTextureNoise(samples, 0, pixelClass)[120], expected, 0.08 * expected)
            << "class " << pixelClass;
    }
    const BackgroundSubtraction subtraction(samples, BackgroundOptions{});
    cv::Mat mask;
    int falsePixels = 0;
    for (int frame = 0; frame < 20; ++frame) {
        subtraction.segment(exposeMosaic(still), mask);
        falsePixels += cv::countNonZero(mask);
    }
    // About one per frame by design; Poisson with mean 20 stays below 40.
    EXPECT_LT(falsePixels, 40);
}

TEST(TextureNoise, AHandPassingThroughTheSamplesDoesNotInflateIt) {
    cv::RNG rng(4);
    const cv::Mat still = scene();
    std::vector<cv::Mat> clean, passing;
    for (int i = 0; i < 15; ++i) {
        clean.push_back(expose(still, rng));
        passing.push_back(i % 5 == 2 ? expose(withHand(still, {10 * i, 40, 12, 30}), rng) : clean.back());
    }
    const NoiseTable reference = estimateTextureNoise(clean, 1, 1),
                     measured = estimateTextureNoise(passing, 1, 1);
    for (int level : {60, 128, 200})
        EXPECT_NEAR(measured[level], reference[level], 0.1 * reference[level]) << "level " << level;
}

TEST(NoiseThreshold, IsTheGaussianTailThatLeavesTheAskedFalsePixels) {
    // One channel, one false pixel in a million: two-sided tail 1e-6.
    EXPECT_NEAR(noiseThresholdSigmas(1.0, 1000000, 1), 4.8916, 1e-3);
    // Three channels share the pixel's probability.
    const double k = noiseThresholdSigmas(1.0, 1000000, 3);
    EXPECT_NEAR(std::erfc(k / std::sqrt(2.0)), 1e-6 / 3.0, 1e-9);
    EXPECT_GT(noiseThresholdSigmas(0.1, 1000000, 1), 4.8916);
}

TEST(BackgroundSubtraction, FindsTheHandAndLeavesNoiseAlone) {
    cv::RNG rng(5);
    const cv::Mat still = scene();
    std::vector<cv::Mat> samples;
    // The hand passes through a third of the samples, never twice at one place: the median is the table.
    for (int i = 0; i < 15; ++i)
        samples.push_back(expose(i % 3 == 0 ? withHand(still, {15 * i, 20, 14, 40}) : still, rng));
    const BackgroundSubtraction subtraction(samples, BackgroundOptions{});
    // The median of 15 samples is within a few of its noise sigmas (0.8 DN at the brightest) of the table
    // everywhere, also where the hand passed.
    cv::Mat table, difference;
    still.convertTo(table, CV_8UC3);
    cv::absdiff(subtraction.background(), table, difference);
    EXPECT_LE(cv::norm(difference, cv::NORM_INF), 5.0);

    const cv::Rect hand(100, 60, 50, 70);
    cv::Mat handTruth(still.size(), CV_8UC1, cv::Scalar(0));
    handTruth(hand).setTo(255);
    int missed = 0, falsePixels = 0;
    const int frames = 10;
    cv::Mat mask;
    for (int frame = 0; frame < frames; ++frame) {
        subtraction.segment(expose(withHand(still, hand), rng), mask);
        ASSERT_EQ(mask.type(), CV_8UC1);
        missed += cv::countNonZero(handTruth & ~mask);
        falsePixels += cv::countNonZero(mask & ~handTruth);
    }
    EXPECT_EQ(missed, 0);
    // About one false pixel per frame by design; Poisson with mean 10 stays below 25.
    EXPECT_LT(falsePixels, 25);
}

TEST(BackgroundSubtraction, WorksOnGrayFrames) {
    cv::RNG rng(6);
    cv::Mat still;
    cv::extractChannel(scene(), still, 1);
    auto exposeGray = [&](const cv::Mat& truth) {
        cv::Mat noise(truth.size(), CV_32FC1), image;
        rng.fill(noise, cv::RNG::NORMAL, 0.0, std::sqrt(noiseVariance(128)));
        cv::Mat(truth + noise).convertTo(image, CV_8UC1);
        return image;
    };
    std::vector<cv::Mat> samples;
    for (int i = 0; i < 15; ++i)
        samples.push_back(exposeGray(still));
    const BackgroundSubtraction subtraction(samples, BackgroundOptions{});
    cv::Mat handScene = still.clone();
    handScene(cv::Rect(20, 20, 30, 30)) += 40.0f;
    cv::Mat mask;
    subtraction.segment(exposeGray(handScene), mask);
    EXPECT_EQ(cv::countNonZero(mask(cv::Rect(20, 20, 30, 30))), 900);
    EXPECT_LT(cv::countNonZero(mask) - 900, 10);
}

TEST(BackgroundSubtraction, RefusesTooFewSamples) {
    cv::RNG rng(7);
    const std::vector<cv::Mat> samples{expose(scene(), rng), expose(scene(), rng)};
    EXPECT_THROW(BackgroundSubtraction(samples, BackgroundOptions{}), std::invalid_argument);
    BackgroundOptions options;
    options.samples = 2;
    EXPECT_TRUE(options.validate());
}

}  // namespace
}  // namespace everytouch::eval
