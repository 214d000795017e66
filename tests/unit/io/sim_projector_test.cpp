#include "io/sim_projector.h"

#include <stdexcept>
#include <thread>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>

#include "core/code_image.h"
#include "core/geometry.h"
#include "core/projector_chessboard.h"

namespace everytouch::io {
namespace {

// The texture of the next pair the source delivers.
cv::Mat nextTexture(SimSource& source) {
    core::FramePair pair;
    pair.positive = *source.next();
    pair.negative = *source.next();
    cv::Mat subtraction, texture;
    core::computeSubtractionAndTexture(pair, subtraction, texture);
    return texture;
}

core::ChessboardOptions board() {
    core::ChessboardOptions options;
    options.squarePx = 40;
    return options;
}

TEST(SimProjector, TheSimulatedCameraSeesWhatItShowsUntilReleased) {
    SimSource source(RigSpec::parse("sim:table-setup"), false);
    SimProjector projector(source);
    EXPECT_EQ(projector.size(), source.rig()->calibration.projectorSize);
    EXPECT_THAT(projector.describe(), ::testing::HasSubstr("simulated projector"));
    EXPECT_FALSE(core::detectProjectedChessboard(nextTexture(source), board(), projector.size()).ok());

    cv::Mat image;
    core::renderProjectorChessboard(board(), projector.size(), image);
    projector.show(image);
    EXPECT_TRUE(core::detectProjectedChessboard(nextTexture(source), board(), projector.size()).ok());
    projector.release();
    EXPECT_FALSE(core::detectProjectedChessboard(nextTexture(source), board(), projector.size()).ok());

    EXPECT_THROW(projector.show(cv::Mat(10, 10, CV_8UC1)), std::invalid_argument);
}

// Mean level of the texture around a camera pixel (3 x 3).
double levelAt(const cv::Mat& texture, const Eigen::Vector2d& camera) {
    cv::Mat gray;
    cv::cvtColor(texture, gray, cv::COLOR_BGR2GRAY);
    const cv::Rect around(static_cast<int>(camera.x()) - 1, static_cast<int>(camera.y()) - 1, 3, 3);
    return cv::mean(gray(around))[0];
}

TEST(SimProjector, DrawsTheDesktopThroughTheKeystoneItIsGiven) {
    // White content on the table: the display is lit, the rest of the panel is black.
    SimSource source(RigSpec::parse("sim:table-setup"), false);
    SimProjector projector(source);
    const core::Calibration rig = source.rig()->calibration;
    // The display on the middle of the panel at half its size.
    Eigen::Matrix3d keystone;
    keystone << 0.5, 0, 160, 0, 0.5, 120, 0, 0, 1;
    projector.setDisplayToProjector({640, 480}, keystone);
    const cv::Mat texture = nextTexture(source);
    const auto camera = [&](double x, double y) {
        return core::applyHomography(rig.projectorToCameraHomography(), Eigen::Vector2d(x, y));
    };
    // Eight panel pixels inside and outside each edge of that rectangle: the projector's white on top of the
    // room light, and the room light alone.
    for (const auto& [inside, outside] :
         {std::pair{camera(320, 128), camera(320, 112)}, std::pair{camera(320, 352), camera(320, 368)},
          std::pair{camera(168, 240), camera(152, 240)}, std::pair{camera(472, 240), camera(488, 240)}})
        EXPECT_GT(levelAt(texture, inside), levelAt(texture, outside) + 50.0)
            << levelAt(texture, inside) << " inside, " << levelAt(texture, outside) << " outside";
    // The rig describes the display it now shows.
    EXPECT_TRUE(source.rig()->calibration.displayToProjector.isApprox(keystone));

    EXPECT_THROW(projector.setDisplayToProjector({0, 480}, keystone), std::invalid_argument);
    EXPECT_THROW(projector.setDisplayToProjector({640, 480}, Eigen::Matrix3d::Zero()), std::invalid_argument);
}

TEST(SimProjector, HandsAndTheirTruthFollowTheDisplayShown) {
    // The same frame of a drag, a finger down on the display, under the rig's keystone and under another
    // that moves and turns the display: the finger touches the same display point, now elsewhere on the
    // table.
    const RigSpec spec = RigSpec::parse("sim:drag,seed=2,start=1.9");
    SimSource own(spec, false), moved(spec, false);
    SimProjector projector(moved);
    const core::Calibration rig = own.rig()->calibration;
    const Eigen::Matrix3d turn = (Eigen::Matrix3d() << std::cos(0.05), -std::sin(0.05), 30, std::sin(0.05),
                                  std::cos(0.05), -20, 0, 0, 1)
                                     .finished();
    projector.setDisplayToProjector(rig.displaySize, rig.displayToProjector * turn);
    ASSERT_TRUE(own.next() && moved.next());
    ASSERT_EQ(own.truth()->size(), 1u);
    ASSERT_EQ(moved.truth()->size(), 1u);
    const core::FingerTruth before = own.truth()->front();
    const core::FingerTruth after = moved.truth()->front();
    EXPECT_EQ(after.heightMm, 0.0);
    // Within the reach of the finger's inverse kinematics, a few hundredths of a millimetre.
    EXPECT_NEAR(after.x, before.x, 0.1);
    EXPECT_NEAR(after.y, before.y, 0.1);
    // Where the truth says the finger is, in the camera: the display point, through the keystone shown.
    const auto cameraOf = [&](const Eigen::Matrix3d& displayToProjector, double x, double y) {
        return core::applyHomography(rig.projectorToCameraHomography() * displayToProjector,
                                     Eigen::Vector2d(x, y));
    };
    const sim::FingertipTruth& tip = moved.frameTruth().fingertips[after.id];
    EXPECT_LT((cameraOf(rig.displayToProjector * turn, after.x, after.y) -
               Eigen::Vector2d(tip.camera.x, tip.camera.y))
                  .norm(),
              0.01);
    EXPECT_GT(
        (cameraOf(rig.displayToProjector, before.x, before.y) - Eigen::Vector2d(tip.camera.x, tip.camera.y))
            .norm(),
        10.0);
}

TEST(SimProjector, ShowsWhileAnotherThreadTakesFrames) {
    SimSource source(RigSpec::parse("sim:table-setup,duration=0.1"), false);
    SimProjector projector(source);
    std::thread camera([&source] {
        while (source.next()) {
        }
    });
    cv::Mat image;
    core::renderProjectorChessboard(board(), projector.size(), image);
    for (int i = 0; i < 5; ++i) {
        projector.show(image);
        projector.release();
    }
    camera.join();
}

}  // namespace
}  // namespace everytouch::io
