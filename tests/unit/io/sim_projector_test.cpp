#include "io/sim_projector.h"

#include <stdexcept>
#include <thread>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "core/code_image.h"
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
