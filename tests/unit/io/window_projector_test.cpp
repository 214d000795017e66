#include "io/window_projector.h"

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <thread>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <opencv2/core/eigen.hpp>
#include <opencv2/imgproc.hpp>

#include "core/embedding.h"
#include "core/pattern.h"
#include "core/projector_chessboard.h"
#include "io/input_error.h"
#include "io/recording.h"
#include "support/screen_grabs.h"
#include "support/temp_dir.h"
#include "support/virtual_display.h"

namespace everytouch::io {
namespace {

using ::testing::HasSubstr;

constexpr int kDelta = 10;
const cv::Size kScreen(400, 300);

core::ChessboardOptions smallBoard() {
    core::ChessboardOptions options;
    options.squarePx = 30;
    return options;
}

class WindowProjectorTest : public ::testing::Test {
protected:
    void SetUp() override {
        ::setenv("DISPLAY", display_.name().c_str(), 1);
        ::unsetenv("WAYLAND_DISPLAY");
        ::unsetenv("SDL_VIDEODRIVER");
    }

    test::VirtualDisplay display_{kScreen};
};

TEST_F(WindowProjectorTest, ShowsAnImageWithTheCodeAddedAndTakenAwayOnAlternateRefreshes) {
    WindowProjector window("", 7, kDelta, {});
    ASSERT_EQ(window.size(), kScreen);
    EXPECT_THAT(window.describe(), HasSubstr("x11 display 0"));
    ASSERT_EQ(window.pattern().size(), kScreen);
    ASSERT_EQ(window.pattern().type(), CV_8UC1);

    cv::Mat board;
    core::renderProjectorChessboard(smallBoard(), kScreen, board);
    window.show(board);
    cv::Mat boardColour, positive, negative;
    cv::cvtColor(board, boardColour, cv::COLOR_GRAY2BGR);
    core::embedCode(boardColour, window.pattern(), kDelta, positive, negative);

    const test::AlternateGrabs grabbed = test::grabAlternates(display_, positive, negative);
    ASSERT_FALSE(grabbed.positive.empty()) << "the screen never showed I = O + P";
    ASSERT_FALSE(grabbed.negative.empty()) << "the screen never showed I' = O - P";
    EXPECT_EQ(grabbed.others, 0);
    // What the camera subtracts is the code, 2 delta on its 1-bits and nothing elsewhere...
    cv::Mat difference;
    cv::subtract(grabbed.positive, grabbed.negative, difference, cv::noArray(), CV_16S);
    cv::Mat bits;
    window.pattern().convertTo(bits, CV_16S, 2.0 * kDelta);
    cv::Mat channels[3];
    cv::split(difference, channels);
    for (const cv::Mat& channel : channels)
        EXPECT_EQ(cv::norm(channel, bits, cv::NORM_INF), 0.0);
    // ...and what people (and the calibration) see is the board, which the calibration's detector finds.
    cv::Mat average;
    cv::addWeighted(grabbed.positive, 0.5, grabbed.negative, 0.5, 0.0, average);
    const auto detection = core::detectProjectedChessboard(average, smallBoard(), kScreen);
    ASSERT_TRUE(detection.ok()) << detection.failure().message;
    const std::vector<Eigen::Vector2d> corners = core::projectorChessboardCorners(smallBoard(), kScreen);
    ASSERT_EQ(detection.value().cameraCorners.size(), corners.size());
    for (std::size_t k = 0; k < corners.size(); ++k)
        EXPECT_LT((detection.value().cameraCorners[k] - corners[k]).norm(), 0.5) << "corner " << k;
}

TEST_F(WindowProjectorTest, BetweenImagesTheDisplayAreaIsWhiteThroughTheKeystoneWithTheCode) {
    WindowProjector window("screen", 3, kDelta, {});
    // A display of 600 x 400 drawn at half size, its corner at (50, 40) of the panel.
    Eigen::Matrix3d displayToProjector;
    displayToProjector << 0.5, 0.0, 50.0, 0.0, 0.5, 40.0, 0.0, 0.0, 1.0;
    window.setDisplayToProjector(cv::Size(600, 400), displayToProjector);
    cv::Mat board;
    core::renderProjectorChessboard(smallBoard(), kScreen, board);
    window.show(board);
    window.release();

    cv::Mat keystone, content, positive, negative;
    cv::eigen2cv(displayToProjector, keystone);
    cv::warpPerspective(cv::Mat(400, 600, CV_8UC3, cv::Scalar::all(255)), content, keystone, kScreen);
    core::embedCode(content, window.pattern(), kDelta, positive, negative);
    const test::AlternateGrabs grabbed = test::grabAlternates(display_, positive, negative);
    EXPECT_FALSE(grabbed.positive.empty());
    EXPECT_FALSE(grabbed.negative.empty());
    EXPECT_EQ(grabbed.others, 0);
}

// Generating the pattern takes a minute on a large panel: the next start reads it where the first kept it.
TEST_F(WindowProjectorTest, KeepsItsPatternForTheNextStartAndGeneratesItAgainWhenTheKeptOneIsBad) {
    test::TempDir state;
    const std::filesystem::path kept = state.path() / "pattern-seed9-400x300.png";
    core::PatternOptions options;
    options.size = kScreen;
    options.seed = 9;
    const cv::Mat generated = core::generatePattern(options);
    {
        WindowProjector window("", 9, kDelta, state.path());
        EXPECT_EQ(cv::norm(window.pattern(), generated, cv::NORM_INF), 0.0);
    }
    ASSERT_TRUE(std::filesystem::exists(kept));
    EXPECT_EQ(cv::norm(readPatternImage(kept, kScreen), generated, cv::NORM_INF), 0.0);

    // What is kept is what the next start shows: here another pattern, put in its place.
    cv::Mat other = 1 - generated;
    writePatternImage(kept, other);
    {
        WindowProjector window("", 9, kDelta, state.path());
        EXPECT_EQ(cv::norm(window.pattern(), other, cv::NORM_INF), 0.0);
    }
    // A kept file that is not a pattern of this size is generated again and replaced.
    std::ofstream(kept, std::ios::trunc) << "not a png";
    {
        WindowProjector window("", 9, kDelta, state.path());
        EXPECT_EQ(cv::norm(window.pattern(), generated, cv::NORM_INF), 0.0);
    }
    EXPECT_EQ(cv::norm(readPatternImage(kept, kScreen), generated, cv::NORM_INF), 0.0);
}

TEST_F(WindowProjectorTest, RefusesWhatItCannotShow) {
    WindowProjector window("0", 1, kDelta, {});
    EXPECT_THROW(window.show(cv::Mat(100, 100, CV_8UC1, cv::Scalar(0))), std::invalid_argument);
    EXPECT_THROW(window.show(cv::Mat(kScreen, CV_16UC1, cv::Scalar(0))), std::invalid_argument);
    EXPECT_THROW(window.setDisplayToProjector(cv::Size(640, 480), Eigen::Matrix3d::Zero()),
                 std::invalid_argument);
    EXPECT_THROW(window.setDisplayToProjector(cv::Size(), Eigen::Matrix3d::Identity()),
                 std::invalid_argument);
}

TEST_F(WindowProjectorTest, AnUnknownDisplayIsRefusedNamingThoseThatExist) {
    try {
        WindowProjector window("HDMI-9", 1, kDelta, {});
        FAIL() << "opened a display that does not exist";
    } catch (const InputError& error) {
        EXPECT_THAT(error.what(), HasSubstr("[Projector] Display=: HDMI-9: no such display"));
        EXPECT_THAT(error.what(), HasSubstr("0 \"screen\" (400x300)"));
    }
    EXPECT_THROW(WindowProjector("", 1, 0, {}), InputError);
    EXPECT_THROW(WindowProjector("", 1, 128, {}), InputError);
}

TEST(WindowProjectorWithoutDisplay, SaysThatNoDisplayServerIsReachable) {
    if (std::filesystem::exists("/dev/dri"))
        GTEST_SKIP() << "this machine has a KMS device, on which the window could open";
    ::unsetenv("DISPLAY");
    ::unsetenv("WAYLAND_DISPLAY");
    ::unsetenv("SDL_VIDEODRIVER");
    try {
        WindowProjector window("", 1, kDelta, {});
        FAIL() << "opened a window without a display server";
    } catch (const std::runtime_error& error) {
        EXPECT_THAT(error.what(), HasSubstr("no display server is reachable for the projector window"));
    }
}

}  // namespace
}  // namespace everytouch::io
