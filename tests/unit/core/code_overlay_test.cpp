#include "core/code_overlay.h"

#include <cmath>
#include <functional>

#include <gtest/gtest.h>
#include <opencv2/core.hpp>

#include "core/embedding.h"

namespace everytouch::core {
namespace {

// A compositor's "over" in 8 bits with premultiplied colours, result = overlay + desktop (255 - alpha) / 255,
// as two kinds of compositor round it: pixman's (X11's Render extension, picom's xrender backend) and a GL
// compositor's, which blends in floating point and rounds to the nearest level.
using Over = std::function<int(int overlay, int alpha, int desktop)>;

int pixmanOver(int overlay, int alpha, int desktop) {
    const int t = desktop * (255 - alpha) + 0x80;
    return overlay + (((t >> 8) + t) >> 8);
}

int glOver(int overlay, int alpha, int desktop) {
    const double result = overlay / 255.0 + desktop / 255.0 * (1.0 - alpha / 255.0);
    return static_cast<int>(std::lround(255.0 * result));
}

// Every desktop level under a 1-bit and a 0-bit, composited with both overlays.
struct Composited {
    cv::Mat desktop;             // CV_8UC1, 1 x 512: levels 0..255 twice
    cv::Mat bits;                // 0 for the first 256, 1 for the rest
    cv::Mat positive, negative;  // CV_32SC1: what people and the camera see in each refresh
};

Composited composite(int delta, const Over& over) {
    Composited c;
    c.desktop.create(1, 512, CV_8UC1);
    c.bits.create(1, 512, CV_8UC1);
    for (int x = 0; x < 512; ++x) {
        c.desktop.at<uchar>(x) = static_cast<uchar>(x % 256);
        c.bits.at<uchar>(x) = x < 256 ? 0 : 1;
    }
    cv::Mat plus, minus;
    makeCodeOverlay(c.bits, delta, plus, minus);
    c.positive.create(1, 512, CV_32SC1);
    c.negative.create(1, 512, CV_32SC1);
    for (int x = 0; x < 512; ++x) {
        const int d = c.desktop.at<uchar>(x);
        for (int channel = 0; channel < 3; ++channel) {
            const cv::Vec4b p = plus.at<cv::Vec4b>(x), m = minus.at<cv::Vec4b>(x);
            EXPECT_EQ(p[channel], p[0]);  // grey: the same on every channel
            EXPECT_EQ(m[channel], m[0]);
        }
        c.positive.at<int>(x) = over(plus.at<cv::Vec4b>(x)[0], plus.at<cv::Vec4b>(x)[3], d);
        c.negative.at<int>(x) = over(minus.at<cv::Vec4b>(x)[0], minus.at<cv::Vec4b>(x)[3], d);
    }
    return c;
}

class CodeOverlay : public ::testing::TestWithParam<int> {};

TEST_P(CodeOverlay, TheDifferenceIsTwiceDeltaOnOnesAndZeroOnZerosWhateverTheDesktopShows) {
    const int delta = GetParam();
    for (const Over& over : {Over(pixmanOver), Over(glOver)}) {
        const Composited c = composite(delta, over);
        for (int x = 0; x < 512; ++x) {
            const int difference = c.positive.at<int>(x) - c.negative.at<int>(x);
            ASSERT_EQ(difference, c.bits.at<uchar>(x) ? 2 * delta : 0)
                << "desktop level " << int{c.desktop.at<uchar>(x)} << ", bit " << int{c.bits.at<uchar>(x)};
            ASSERT_GE(c.negative.at<int>(x), 0);
            ASSERT_LE(c.positive.at<int>(x), 255);
        }
    }
}

TEST_P(CodeOverlay, PeopleSeeTheDesktopCompressedAndNoTraceOfThePattern) {
    const int delta = GetParam();
    for (const Over& over : {Over(pixmanOver), Over(glOver)}) {
        const Composited c = composite(delta, over);
        for (int level = 0; level < 256; ++level) {
            const int underZero = c.positive.at<int>(level) + c.negative.at<int>(level);
            const int underOne = c.positive.at<int>(256 + level) + c.negative.at<int>(256 + level);
            ASSERT_EQ(underZero, underOne) << "desktop level " << level;
            EXPECT_NEAR(underZero / 2.0, delta + level * (255.0 - 2 * delta) / 255.0, 0.5)
                << "desktop level " << level;
        }
    }
}

TEST_P(CodeOverlay, TheRefreshesAreTheImagesTheCodeIsEmbeddedInWithinOneLevel) {
    const int delta = GetParam();
    const Composited c = composite(delta, pixmanOver);
    cv::Mat embeddedPlus, embeddedMinus;
    embedCode(c.desktop, c.bits, delta, embeddedPlus, embeddedMinus);
    for (int x = 0; x < 512; ++x) {
        EXPECT_NEAR(c.positive.at<int>(x), embeddedPlus.at<uchar>(x), 1) << "at " << x;
        EXPECT_NEAR(c.negative.at<int>(x), embeddedMinus.at<uchar>(x), 1) << "at " << x;
    }
}

INSTANTIATE_TEST_SUITE_P(Deltas, CodeOverlay, ::testing::Values(1, 6, 10, 20, 64, 127));

TEST(CodeOverlayInput, RefusesADeltaOutsideOneTo127AndBitsThatAreNotOneByteAPixel) {
    cv::Mat bits(4, 4, CV_8UC1, cv::Scalar(1)), plus, minus;
    EXPECT_THROW(makeCodeOverlay(bits, 0, plus, minus), cv::Exception);
    EXPECT_THROW(makeCodeOverlay(bits, 128, plus, minus), cv::Exception);
    EXPECT_THROW(makeCodeOverlay(cv::Mat(4, 4, CV_16UC1, cv::Scalar(1)), 10, plus, minus), cv::Exception);
    EXPECT_NO_THROW(makeCodeOverlay(bits, 127, plus, minus));
    EXPECT_EQ(plus.type(), CV_8UC4);
    EXPECT_EQ(plus.at<cv::Vec4b>(0, 0), cv::Vec4b(254, 254, 254, 254));
    EXPECT_EQ(minus.at<cv::Vec4b>(0, 0), cv::Vec4b(0, 0, 0, 254));
}

}  // namespace
}  // namespace everytouch::core
