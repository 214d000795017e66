#include "core/still_scene.h"

#include <cmath>

#include <gtest/gtest.h>
#include <opencv2/core.hpp>

namespace everytouch::core {
namespace {

constexpr int kBlockPx = 4;
constexpr double kPixelNoise = 1.5;  // DN, each frame's own

// A table with printed content and a code, seen with fresh camera noise in every pair.
class StillSceneTest : public ::testing::Test {
protected:
    void SetUp() override {
        cv::RNG rng(11);
        content_.create(size_, CV_32FC3);
        rng.fill(content_, cv::RNG::UNIFORM, 60.0, 200.0);
        code_.create(size_, CV_32FC1);
        rng.fill(code_, cv::RNG::UNIFORM, 0.0, 2.0);
        code_.forEach<float>([](float& bit, const int*) { bit = bit < 1.0f ? -20.0f : 20.0f; });
        scene_.setRegion(region_, kBlockPx);
    }

    // One pair's T and S with `change` added to T inside `where`.
    void observe(cv::Mat& texture, cv::Mat& subtraction, const cv::Rect& where = {}, double change = 0.0) {
        cv::Mat t = content_.clone(), s = code_.clone();
        cv::Mat noise(size_, CV_32FC3);
        rng_.fill(noise, cv::RNG::NORMAL, 0.0, kPixelNoise);
        t += noise;
        if (!where.empty())
            t(where) += cv::Scalar::all(change);
        cv::Mat sNoise(size_, CV_32FC1);
        rng_.fill(sNoise, cv::RNG::NORMAL, 0.0, kPixelNoise * std::sqrt(2.0));
        s += sNoise;
        t.convertTo(texture, CV_8UC3);
        s.convertTo(subtraction, CV_16SC1);
    }

    // Observes the unchanged scene three times: the noise is learned from the first and the third, which
    // share no frame, and the third is the reference.
    void settle() {
        cv::Mat t, s;
        for (int i = 0; i < 3; ++i) {
            observe(t, s);
            scene_.matchesReference(t, s);
            scene_.adoptAsReference();
        }
    }

    const cv::Size size_{320, 240};
    const cv::Rect region_{40, 32, 240, 176};
    cv::Mat content_, code_;
    cv::RNG rng_{5};
    StillScene scene_;
};

TEST_F(StillSceneTest, NothingMatchesBeforeAReferenceAndTheNoiseAreKnown) {
    cv::Mat t, s;
    observe(t, s);
    EXPECT_FALSE(scene_.matchesReference(t, s));
    scene_.adoptAsReference();
    EXPECT_EQ(scene_.textureNoise(130.0), 0.0);
}

TEST_F(StillSceneTest, TheSameSceneUnderFreshNoiseMatches) {
    settle();
    cv::Mat t, s;
    for (int i = 0; i < 50; ++i) {
        observe(t, s);
        EXPECT_TRUE(scene_.matchesReference(t, s)) << "pair " << i;
    }
}

TEST_F(StillSceneTest, LearnsTheNoiseOfABlocksDifference) {
    settle();
    // Two pairs' independent noise over 16 pixels; T's rounding to 8 bits adds 1/12 DN^2 a pixel.
    const double expected = std::sqrt(2.0 * (kPixelNoise * kPixelNoise + 1.0 / 12.0) / (kBlockPx * kBlockPx));
    EXPECT_NEAR(scene_.textureNoise(130.0), expected, 0.1 * expected);
    EXPECT_GT(scene_.subtractionNoise(130.0), 0.0);
}

TEST_F(StillSceneTest, AFingertipSizedChangeIsSeen) {
    settle();
    cv::Mat t, s;
    // A 12 x 12 px patch a few DN brighter: far beyond the noise of a block's mean (0.5 DN), well within
    // what a fingertip changes.
    observe(t, s, cv::Rect(150, 110, 12, 12), 4.0);
    EXPECT_FALSE(scene_.matchesReference(t, s));
}

TEST_F(StillSceneTest, AChangeOutsideTheRegionIsIgnored) {
    settle();
    cv::Mat t, s;
    observe(t, s, cv::Rect(0, 0, 32, 240), 80.0);
    EXPECT_TRUE(scene_.matchesReference(t, s));
}

TEST_F(StillSceneTest, ChangesAddUpAgainstTheReference) {
    settle();
    // The light fading by 0.3 DN a pair: no pair differs from the last by more than the noise, but the
    // scene soon differs from the reference.
    cv::Mat t, s;
    int matched = 0;
    for (int i = 1; i <= 40; ++i) {
        observe(t, s, region_, -0.3 * i);
        matched += scene_.matchesReference(t, s) ? 1 : 0;
    }
    EXPECT_LT(matched, 20);
}

TEST_F(StillSceneTest, MovingContentNeverRaisesTheNoise) {
    settle();
    const double learned = scene_.textureNoise(130.0);
    cv::Mat t, s;
    cv::Mat motion(size_, CV_32FC3);
    for (int i = 0; i < 5; ++i) {
        rng_.fill(motion, cv::RNG::UNIFORM, -30.0, 30.0);
        content_ += motion;
        observe(t, s);
        EXPECT_FALSE(scene_.matchesReference(t, s));
        scene_.adoptAsReference();
    }
    EXPECT_LE(scene_.textureNoise(130.0), learned);
}

TEST_F(StillSceneTest, ResetForgetsTheReference) {
    settle();
    scene_.reset();
    cv::Mat t, s;
    observe(t, s);
    EXPECT_FALSE(scene_.matchesReference(t, s));
}

}  // namespace
}  // namespace everytouch::core
