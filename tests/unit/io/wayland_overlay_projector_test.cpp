#include "io/wayland_overlay_projector.h"

#include <atomic>
#include <chrono>
#include <cstdlib>
#include <stdexcept>
#include <thread>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "core/embedding.h"
#include "core/projector_chessboard.h"
#include "io/input_error.h"
#include "support/compositor.h"
#include "support/process.h"
#include "support/screen_grabs.h"
#include "support/temp_dir.h"
#include "support/virtual_pointer.h"
#include "support/wait.h"
#include "support/wayland_compositor.h"

namespace everytouch::io::wayland_overlay_test {
namespace {

using ::testing::HasSubstr;
using namespace std::chrono_literals;

constexpr int kOverlayDelta = 10;
const cv::Size kDesktop(320, 240);
const cv::Vec3b kDesktopColour(160, 180, 200);

class WaylandOverlayProjectorTest : public ::testing::Test {
protected:
    void SetUp() override { ::setenv("WAYLAND_DISPLAY", compositor_.socket().c_str(), 1); }
    void TearDown() override { ::unsetenv("WAYLAND_DISPLAY"); }

    // The screen as it shows `positive` and `negative` (opaque images: known to the level).
    test::AlternateGrabs grabAlternates(const cv::Mat& positive, const cv::Mat& negative) {
        return test::grabAlternates([this] { return compositor_.grab(); }, positive, negative);
    }
    test::AlternateGrabs grabTheCodeOverTheDesktop(const cv::Mat& pattern) {
        return test::grabBothPolarities([this] { return compositor_.grab(); }, pattern, kOverlayDelta);
    }

    test::WaylandCompositor compositor_{kDesktop, kDesktopColour};
};

// The code as the camera subtracts it, per channel: 2 delta on the pattern's 1-bits and nothing elsewhere.
// Over the desktop within a level: sway's pixman renderer lays a uniform copy of one of the overlay's pixels
// under it, which takes delta * delta / 255 from the difference.
void expectTheCode(const test::AlternateGrabs& grabbed, const cv::Mat& pattern,
                   double toleranceLevels = 0.0) {
    ASSERT_FALSE(grabbed.positive.empty()) << "the screen never showed the \"+\" image";
    ASSERT_FALSE(grabbed.negative.empty()) << "the screen never showed the \"-\" image";
    cv::Mat difference, bits;
    cv::subtract(grabbed.positive, grabbed.negative, difference, cv::noArray(), CV_16S);
    pattern.convertTo(bits, CV_16S, 2.0 * kOverlayDelta);
    cv::Mat channels[3];
    cv::split(difference, channels);
    for (const cv::Mat& channel : channels)
        EXPECT_LE(cv::norm(channel, bits, cv::NORM_INF), toleranceLevels);
}

TEST_F(WaylandOverlayProjectorTest, BlendsTheCodeOverTheDesktopOnAlternateFrames) {
    WaylandOverlayProjector overlay("", 5, kOverlayDelta, {});
    ASSERT_EQ(overlay.size(), kDesktop);
    EXPECT_THAT(overlay.describe(), HasSubstr("the overlay on the Wayland compositor " +
                                              compositor_.socket() + " output 0 \"HEADLESS-1\" (320x240)"));
    EXPECT_FALSE(overlay.drawsDisplayThroughKeystone());
    EXPECT_FALSE(overlay.problem());
    ASSERT_EQ(overlay.pattern().size(), kDesktop);

    const test::AlternateGrabs grabbed = grabTheCodeOverTheDesktop(overlay.pattern());
    expectTheCode(grabbed, overlay.pattern(), 1.0);
    if (HasFatalFailure())
        return;
    // What people see is the desktop, translucently covered, with no trace of the pattern: the average of
    // the two images is one colour, within 2 delta of the desktop's.
    cv::Mat average;
    cv::addWeighted(grabbed.positive, 0.5, grabbed.negative, 0.5, 0.0, average);
    for (int channel = 0; channel < 3; ++channel) {
        cv::Mat plane;
        cv::extractChannel(average, plane, channel);
        double low = 0.0, high = 0.0;
        cv::minMaxLoc(plane, &low, &high);
        EXPECT_LE(high - low, 1.0) << "the average shows the pattern in channel " << channel;
        EXPECT_NEAR(low, kDesktopColour[channel], 2.0 * kOverlayDelta);
    }

    // One image per frame the compositor asks for: its headless output runs at 60 Hz.
    const std::uint64_t before = overlay.presented();
    std::this_thread::sleep_for(500ms);
    EXPECT_GE(overlay.presented() - before, 15u);
    EXPECT_LE(overlay.presented() - before, 33u);
}

TEST_F(WaylandOverlayProjectorTest, ShowsACalibrationImageOpaqueWithTheCodeAndThenTheDesktopAgain) {
    WaylandOverlayProjector overlay("HEADLESS-1", 5, kOverlayDelta, {});
    core::ChessboardOptions board;
    board.squarePx = 20;
    cv::Mat image, colour, positive, negative;
    core::renderProjectorChessboard(board, kDesktop, image);
    overlay.show(image);
    cv::cvtColor(image, colour, cv::COLOR_GRAY2BGR);
    core::embedCode(colour, overlay.pattern(), kOverlayDelta, positive, negative);
    expectTheCode(grabAlternates(positive, negative), overlay.pattern());

    overlay.release();
    expectTheCode(grabTheCodeOverTheDesktop(overlay.pattern()), overlay.pattern(), 1.0);
}

// The overlay takes no input: a click where it covers the desktop reaches the window below. wev, a real
// client that prints what the compositor sends it, fills the output, and a virtual mouse clicks at its
// centre.
TEST_F(WaylandOverlayProjectorTest, AClickOnItReachesTheWindowBelow) {
    test::TempDir runtime;
    // Line-buffered: wev's output goes to a file the test reads while it runs.
    test::BackgroundProcess window(
        {"stdbuf", "-oL", "wev"}, runtime / "wev.log",
        {{"WAYLAND_DISPLAY", compositor_.socket()}, {"XDG_RUNTIME_DIR", runtime.path().string()}});
    ASSERT_TRUE(window.waitForOutput("activated", 10s)) << "wev's window never showed: " << window.output();
    WaylandOverlayProjector overlay("", 5, kOverlayDelta, {});
    ASSERT_TRUE(test::waitUntil([&] { return overlay.presented() > 2; }, 5s));

    test::VirtualPointer mouse(compositor_.socket());
    mouse.moveTo(kDesktop.width / 2, kDesktop.height / 2, kDesktop.width, kDesktop.height);
    // The pointer's focus is the window's (its input region), not the overlay's.
    ASSERT_TRUE(window.waitForOutput("wl_pointer] enter", 5s)) << window.output();
    mouse.click();
    EXPECT_TRUE(window.waitForOutput("button: 272 (left), state: 1 (pressed)", 5s)) << window.output();
    EXPECT_TRUE(window.waitForOutput("button: 272 (left), state: 0 (released)", 5s)) << window.output();
    EXPECT_FALSE(overlay.problem());
}

TEST_F(WaylandOverlayProjectorTest, AnUnknownOutputIsRefusedNamingThoseThatExist) {
    try {
        WaylandOverlayProjector overlay("HDMI-9", 5, kOverlayDelta, {});
        FAIL() << "an unknown output was taken";
    } catch (const InputError& error) {
        EXPECT_THAT(error.what(), HasSubstr("[Projector] Display=: HDMI-9: no such output on the Wayland "
                                            "compositor " +
                                            compositor_.socket() + "; it has 0 \"HEADLESS-1\" (320x240)"));
    }
    EXPECT_THROW(WaylandOverlayProjector("", 5, 0, {}), InputError);
}

TEST_F(WaylandOverlayProjectorTest, SaysSoWhenTheCompositorGoesAwayAndComesBackWithIt) {
    WaylandOverlayProjector overlay("", 5, kOverlayDelta, {});
    std::atomic<int> changes{0};
    overlay.onProblemChange([&] { ++changes; });
    ASSERT_TRUE(test::waitUntil([&] { return overlay.presented() > 0; }, 5s));
    compositor_.stop();
    ASSERT_TRUE(test::waitUntil([&] { return overlay.problem().has_value(); }, 5s));
    EXPECT_THAT(*overlay.problem(), HasSubstr("closed the connection"));
    EXPECT_EQ(changes, 1);

    const std::string socket = compositor_.socket();
    compositor_.start();
    ASSERT_EQ(compositor_.socket(), socket);
    ASSERT_TRUE(test::waitUntil([&] { return !overlay.problem(); }, 5s)) << *overlay.problem();
    EXPECT_EQ(changes, 2);
    expectTheCode(grabTheCodeOverTheDesktop(overlay.pattern()), overlay.pattern(), 1.0);
}

TEST(WaylandOverlayProjectorWithoutCompositor, SaysWhichOneItCannotReach) {
    ::setenv("WAYLAND_DISPLAY", "/nonexistent/wayland-9", 1);
    try {
        WaylandOverlayProjector overlay("", 5, kOverlayDelta, {});
        FAIL() << "the overlay started without a compositor";
    } catch (const std::runtime_error& error) {
        EXPECT_THAT(error.what(), HasSubstr("cannot connect to the Wayland compositor at "
                                            "WAYLAND_DISPLAY=/nonexistent/wayland-9"));
    }
    ::unsetenv("WAYLAND_DISPLAY");
}

}  // namespace
}  // namespace everytouch::io::wayland_overlay_test
