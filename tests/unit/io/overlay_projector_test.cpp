#include "io/overlay_projector.h"

#include <chrono>
#include <cstdlib>
#include <stdexcept>
#include <thread>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "core/code_overlay.h"
#include "core/embedding.h"
#include "core/projector_chessboard.h"
#include "io/input_error.h"
#include "support/compositor.h"
#include "support/desktop_window.h"
#include "support/screen_grabs.h"
#include "support/virtual_display.h"
#include "support/wait.h"

namespace everytouch::io {
namespace {

using ::testing::HasSubstr;
using namespace std::chrono_literals;

constexpr int kOverlayDelta = 10;
const cv::Size kDesktop(320, 240);

// A desktop with every level of every channel somewhere on it.
cv::Mat desktopPicture(cv::Size size) {
    cv::Mat picture(size, CV_8UC3);
    for (int y = 0; y < size.height; ++y)
        for (int x = 0; x < size.width; ++x)
            picture.at<cv::Vec3b>(y, x) = cv::Vec3b(static_cast<uchar>(x * 255 / (size.width - 1)),
                                                    static_cast<uchar>(y * 255 / (size.height - 1)),
                                                    static_cast<uchar>((x * 7 + y * 3) % 256));
    return picture;
}

// The code as the camera subtracts it, per channel: 2 delta on the pattern's 1-bits and nothing elsewhere.
void expectTheCode(const test::AlternateGrabs& grabbed, const cv::Mat& pattern, const cv::Rect& within) {
    ASSERT_FALSE(grabbed.positive.empty()) << "the screen never showed the \"+\" image";
    ASSERT_FALSE(grabbed.negative.empty()) << "the screen never showed the \"-\" image";
    cv::Mat difference;
    cv::subtract(grabbed.positive(within), grabbed.negative(within), difference, cv::noArray(), CV_16S);
    cv::Mat bits;
    pattern(within).convertTo(bits, CV_16S, 2.0 * kOverlayDelta);
    cv::Mat channels[3];
    cv::split(difference, channels);
    for (const cv::Mat& channel : channels)
        EXPECT_EQ(cv::norm(channel, bits, cv::NORM_INF), 0.0);
}

class OverlayProjectorTest : public ::testing::Test {
protected:
    void SetUp() override { ::setenv("DISPLAY", display_.name().c_str(), 1); }

    test::VirtualDisplay display_{kDesktop};
    cv::Mat picture_ = desktopPicture(kDesktop);
    test::DesktopWindow desktop_{display_.name(), cv::Rect(cv::Point(), kDesktop), picture_};
};

class OverlayProjectorComposited : public OverlayProjectorTest {
protected:
    test::Compositor compositor_{display_.name()};
};

TEST_F(OverlayProjectorComposited, BlendsTheCodeOverTheDesktopOnAlternateRefreshes) {
    OverlayProjector overlay("", 5, kOverlayDelta, {});
    ASSERT_EQ(overlay.size(), kDesktop);
    EXPECT_THAT(overlay.describe(), HasSubstr("monitor 0 \"screen\" (320x240)"));
    EXPECT_FALSE(overlay.drawsDisplayThroughKeystone());
    ASSERT_EQ(overlay.pattern().size(), kDesktop);

    cv::Mat positive, negative;
    core::makeCodeOverlay(overlay.pattern(), kOverlayDelta, positive, negative);
    const test::AlternateGrabs grabbed = test::grabAlternates(
        display_, test::compositedOver(positive, picture_), test::compositedOver(negative, picture_));
    expectTheCode(grabbed, overlay.pattern(), cv::Rect(cv::Point(), kDesktop));
    if (HasFatalFailure())
        return;
    // What people see is the desktop at a uniform contrast of (255 - 2 delta) / 255, lifted by delta, over
    // either bit: no trace of the pattern.
    cv::Mat average, expected;
    cv::addWeighted(grabbed.positive, 0.5, grabbed.negative, 0.5, 0.0, average);
    picture_.convertTo(expected, CV_8UC3, (255.0 - 2 * kOverlayDelta) / 255.0, kOverlayDelta);
    EXPECT_LE(cv::norm(average, expected, cv::NORM_INF), 1.0);

    // One image per refresh of the server's (Xvfb's Present runs at 60 Hz).
    const std::uint64_t before = overlay.presented();
    std::this_thread::sleep_for(500ms);
    EXPECT_GE(overlay.presented() - before, 15u);
    EXPECT_LE(overlay.presented() - before, 33u);
}

TEST_F(OverlayProjectorComposited, LetsClicksThroughToTheDesktop) {
    OverlayProjector overlay("", 5, kOverlayDelta, {});
    ASSERT_TRUE(test::waitUntil([&] { return overlay.visible(); }, 5s));
    EXPECT_TRUE(desktop_.clickReaches(cv::Point(160, 120), 2s));
}

TEST_F(OverlayProjectorComposited, StaysAboveWindowsOpenedAfterIt) {
    OverlayProjector overlay("", 5, kOverlayDelta, {});
    ASSERT_TRUE(test::waitUntil([&] { return overlay.visible(); }, 5s));
    const cv::Rect area(40, 30, 200, 150);
    const cv::Mat grey(area.size(), CV_8UC3, cv::Scalar::all(90));
    test::DesktopWindow later(display_.name(), area, grey);
    cv::Mat below = picture_.clone();
    grey.copyTo(below(area));

    cv::Mat positive, negative;
    core::makeCodeOverlay(overlay.pattern(), kOverlayDelta, positive, negative);
    expectTheCode(test::grabAlternates(display_, test::compositedOver(positive, below),
                                       test::compositedOver(negative, below)),
                  overlay.pattern(), area);
}

TEST_F(OverlayProjectorComposited, ShowsACalibrationImageOpaqueWithTheCodeAndThenTheDesktopAgain) {
    OverlayProjector overlay("", 5, kOverlayDelta, {});
    core::ChessboardOptions board;
    board.squarePx = 20;
    cv::Mat image, colour, positive, negative;
    core::renderProjectorChessboard(board, kDesktop, image);
    overlay.show(image);
    cv::cvtColor(image, colour, cv::COLOR_GRAY2BGR);
    core::embedCode(colour, overlay.pattern(), kOverlayDelta, positive, negative);
    expectTheCode(test::grabAlternates(display_, positive, negative), overlay.pattern(),
                  cv::Rect(cv::Point(), kDesktop));

    overlay.release();
    core::makeCodeOverlay(overlay.pattern(), kOverlayDelta, positive, negative);
    expectTheCode(test::grabAlternates(display_, test::compositedOver(positive, picture_),
                                       test::compositedOver(negative, picture_)),
                  overlay.pattern(), cv::Rect(cv::Point(), kDesktop));
}

TEST_F(OverlayProjectorComposited, HidesWhileNoCompositorRunsAndComesBackWithOne) {
    OverlayProjector overlay("", 5, kOverlayDelta, {});
    ASSERT_TRUE(test::waitUntil([&] { return overlay.visible(); }, 5s));

    compositor_.stop();
    ASSERT_TRUE(test::waitUntil([&] { return !overlay.visible(); }, 2s));
    // Its pixels must not cover the desktop as they are.
    EXPECT_TRUE(test::waitUntil([&] { return test::sameImage(display_.grab(), picture_); }, 2s));

    test::Compositor again(display_.name());
    ASSERT_TRUE(test::waitUntil([&] { return overlay.visible(); }, 5s));
    cv::Mat positive, negative;
    core::makeCodeOverlay(overlay.pattern(), kOverlayDelta, positive, negative);
    expectTheCode(test::grabAlternates(display_, test::compositedOver(positive, picture_),
                                       test::compositedOver(negative, picture_)),
                  overlay.pattern(), cv::Rect(cv::Point(), kDesktop));
}

TEST_F(OverlayProjectorTest, RefusesToStartWithoutACompositor) {
    try {
        OverlayProjector overlay("", 5, kOverlayDelta, {});
        FAIL() << "the overlay started without a compositing manager";
    } catch (const std::runtime_error& error) {
        EXPECT_THAT(error.what(), HasSubstr("no compositing manager runs"));
        EXPECT_THAT(error.what(), HasSubstr("Output=window"));
    }
    EXPECT_TRUE(test::sameImage(display_.grab(), picture_));
}

TEST_F(OverlayProjectorComposited, AnUnknownMonitorIsRefusedNamingThoseThatExist) {
    try {
        OverlayProjector overlay("HDMI-9", 5, kOverlayDelta, {});
        FAIL() << "an unknown monitor was taken";
    } catch (const InputError& error) {
        EXPECT_THAT(error.what(), HasSubstr("[Projector] Display=: HDMI-9: no such monitor"));
        EXPECT_THAT(error.what(), HasSubstr("0 \"screen\" (320x240)"));
    }
    EXPECT_THROW(OverlayProjector("", 5, 0, {}), InputError);
}

TEST(OverlayProjectorWithoutDisplay, SaysThatItNeedsAnXServer) {
    ::unsetenv("DISPLAY");
    try {
        OverlayProjector overlay("", 5, kOverlayDelta, {});
        FAIL() << "the overlay started without an X server";
    } catch (const std::runtime_error& error) {
        EXPECT_THAT(
            error.what(),
            HasSubstr(
                "needs a Wayland compositor or an X server, and neither WAYLAND_DISPLAY nor DISPLAY is set"));
    }
}

}  // namespace
}  // namespace everytouch::io
