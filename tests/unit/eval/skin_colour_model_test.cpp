#include "eval/skin_colour_model.h"

#include <gtest/gtest.h>
#include <opencv2/core.hpp>

namespace everytouch::eval {
namespace {

// Colours given as RGB; the model reads BGR images.
cv::Mat oneColour(int r, int g, int b) {
    return cv::Mat(4, 4, CV_8UC3, cv::Scalar(b, g, r));
}

bool isSkin(SkinColourModel& model, int r, int g, int b) {
    cv::Mat mask;
    model.segment(oneColour(r, g, b), mask);
    EXPECT_EQ(mask.type(), CV_8UC1);
    EXPECT_EQ(cv::countNonZero(mask) % 16, 0) << "one colour, one decision";
    return cv::countNonZero(mask) == 16;
}

TEST(SkinColourModel, TellsTypicalSkinTonesFromGreysAndSaturatedColours) {
    SkinColourModel model;
    // Light, medium and dark skin tones under white light.
    EXPECT_TRUE(isSkin(model, 224, 172, 140));
    EXPECT_TRUE(isSkin(model, 190, 125, 90));
    EXPECT_TRUE(isSkin(model, 120, 75, 55));
    // A grey table, white, black, saturated blue and green.
    EXPECT_FALSE(isSkin(model, 128, 128, 128));
    EXPECT_FALSE(isSkin(model, 255, 255, 255));
    EXPECT_FALSE(isSkin(model, 0, 0, 0));
    EXPECT_FALSE(isSkin(model, 30, 60, 200));
    EXPECT_FALSE(isSkin(model, 40, 180, 60));
}

TEST(SkinColourModel, MixturesAreDensitiesOverTheColourCube) {
    // Each mixture's weights sum to one and its kernels lie well inside the cube: the density summed over all
    // 8-bit colours is close to 1 (a coarse 4-DN grid is enough for kernels several DN wide).
    double skin = 0.0, nonSkin = 0.0;
    for (int r = 0; r < 256; r += 4)
        for (int g = 0; g < 256; g += 4)
            for (int b = 0; b < 256; b += 4) {
                skin += SkinColourModel::skinDensity(r + 1.5, g + 1.5, b + 1.5) * 64.0;
                nonSkin += SkinColourModel::nonSkinDensity(r + 1.5, g + 1.5, b + 1.5) * 64.0;
            }
    EXPECT_NEAR(skin, 1.0, 0.05);
    EXPECT_NEAR(nonSkin, 1.0, 0.1);
}

TEST(SkinColourModel, AHigherLikelihoodRatioMarksFewerColours) {
    SkinColourModel lenient(0.1), strict(10.0);
    int lenientCount = 0, strictCount = 0;
    for (int r = 0; r < 256; r += 16)
        for (int g = 0; g < 256; g += 16)
            for (int b = 0; b < 256; b += 16) {
                lenientCount += isSkin(lenient, r, g, b);
                strictCount += isSkin(strict, r, g, b);
            }
    EXPECT_GT(lenientCount, strictCount);
    EXPECT_GT(strictCount, 0);
}

}  // namespace
}  // namespace everytouch::eval
