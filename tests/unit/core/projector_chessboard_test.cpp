#include "core/projector_chessboard.h"

#include <chrono>
#include <stdexcept>

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include "core/geometry.h"
#include "support/surface_renderer.h"
#include "support/test_rig.h"

namespace everytouch::core {
namespace {

using ::testing::HasSubstr;
using ::testing::Optional;

// Largest distance between where the estimate and the truth put the board's corners, camera pixels.
double worstCornerError(const Eigen::Matrix3d& estimate, const Eigen::Matrix3d& truth,
                        const std::vector<Eigen::Vector2d>& projectorCorners) {
    double worst = 0;
    for (const Eigen::Vector2d& corner : projectorCorners)
        worst = std::max(worst, (applyHomography(estimate, corner) - applyHomography(truth, corner)).norm());
    return worst;
}

TEST(ProjectorChessboard, CornersSitWhereFourSquaresMeet) {
    const ChessboardOptions options;
    const cv::Size panel(640, 480);
    cv::Mat image;
    renderProjectorChessboard(options, panel, image);
    const std::vector<Eigen::Vector2d> corners = projectorChessboardCorners(options, panel);
    ASSERT_EQ(corners.size(), 54u);
    for (const Eigen::Vector2d& corner : corners) {
        // The four pixels around a corner (at a pixel boundary) alternate black and white.
        const int x = static_cast<int>(corner.x() + 0.5), y = static_cast<int>(corner.y() + 0.5);
        EXPECT_EQ(image.at<uchar>(y - 1, x - 1), image.at<uchar>(y, x));
        EXPECT_EQ(image.at<uchar>(y - 1, x), image.at<uchar>(y, x - 1));
        EXPECT_NE(image.at<uchar>(y - 1, x - 1), image.at<uchar>(y - 1, x));
    }
    EXPECT_EQ(image.at<uchar>(0, 0), 255);  // a white border
}

TEST(ProjectorChessboard, ValidateNamesTheProblem) {
    ChessboardOptions options;
    options.innerCorners = {8, 6};
    EXPECT_THAT(options.validate({640, 480}), Optional(HasSubstr("odd")));
    options = {};
    options.squarePx = 70;
    EXPECT_THAT(options.validate({640, 480}), Optional(HasSubstr("do not fit")));
    // Options that do not validate are the caller's mistake, not something the frame shows.
    cv::Mat board;
    EXPECT_THROW(renderProjectorChessboard(options, {640, 480}, board), std::invalid_argument);
    const cv::Mat frame(480, 640, CV_8UC1, cv::Scalar(200));
    EXPECT_THROW((void)detectProjectedChessboard(frame, options, {640, 480}), std::invalid_argument);
    EXPECT_THROW((void)estimateProjectorToCamera(frame, options, {640, 480}, CameraModel{}),
                 std::invalid_argument);
}

class ProjectedChessboard : public ::testing::TestWithParam<double> {};

// The board on the table, seen through the paper-like rig: H_CP within a tenth of a pixel of the truth
// without noise and with sigma = 2 DN of sensor noise.
TEST_P(ProjectedChessboard, RecoversTheProjectorToCameraHomography) {
    const double noiseSigmaDn = GetParam();
    test::SurfaceScene scene;
    scene.rig = test::paperLikeCalibration();
    const ChessboardOptions options;
    cv::Mat board;
    renderProjectorChessboard(options, scene.rig.projectorSize, board);
    const cv::Mat capture = test::renderSurface(scene, board, noiseSigmaDn);

    const Result<ProjectorToCameraEstimate> estimate =
        estimateProjectorToCamera(capture, options, scene.rig.projectorSize, CameraModel{});
    ASSERT_TRUE(estimate.ok()) << estimate.failure().message;
    EXPECT_EQ(estimate->inliers, 54);
    const double worst = worstCornerError(estimate->homography, scene.rig.projectorToCameraHomography(),
                                          projectorChessboardCorners(options, scene.rig.projectorSize));
    RecordProperty("rms_px", std::to_string(estimate->rmsPx));
    RecordProperty("worst_corner_error_px", std::to_string(worst));
    EXPECT_LT(estimate->rmsPx, noiseSigmaDn > 0 ? 0.5 : 0.1);
    EXPECT_LT(worst, noiseSigmaDn > 0 ? 0.5 : 0.1);
}

INSTANTIATE_TEST_SUITE_P(NoiseFreeAndNoisy, ProjectedChessboard, ::testing::Values(0.0, 2.0));

TEST(ProjectorChessboard, TellsTheBoardFromItsHalfTurn) {
    // A projector mounted upside down sees the board turned half round; the corners must still pair with the
    // right projector pixels.
    test::SurfaceScene scene;
    scene.rig = test::paperLikeCalibration();
    scene.rig.tableToProjector =
        Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitZ()) * scene.rig.tableToProjector;
    scene.rig.projectorMatrix(0, 2) = scene.rig.projectorSize.width - 1 - scene.rig.projectorMatrix(0, 2);
    scene.rig.projectorMatrix(1, 2) = scene.rig.projectorSize.height - 1 - scene.rig.projectorMatrix(1, 2);
    const ChessboardOptions options;
    cv::Mat board;
    renderProjectorChessboard(options, scene.rig.projectorSize, board);
    const cv::Mat capture = test::renderSurface(scene, board);
    const Result<ProjectorToCameraEstimate> estimate =
        estimateProjectorToCamera(capture, options, scene.rig.projectorSize, CameraModel{});
    ASSERT_TRUE(estimate.ok()) << estimate.failure().message;
    EXPECT_LT(worstCornerError(estimate->homography, scene.rig.projectorToCameraHomography(),
                               projectorChessboardCorners(options, scene.rig.projectorSize)),
              0.1);
}

TEST(ProjectorChessboard, UndistortsTheCornersWithTheCameraModel) {
    test::SurfaceScene scene;
    scene.rig = test::paperLikeCalibration();
    scene.rig.cameraDistortion << -0.2, 0.1, 0, 0, 0;
    const ChessboardOptions options;
    cv::Mat board;
    renderProjectorChessboard(options, scene.rig.projectorSize, board);
    const cv::Mat capture = test::renderSurface(scene, board);
    const CameraModel camera{scene.rig.cameraMatrix, scene.rig.cameraDistortion};
    const Result<ProjectorToCameraEstimate> estimate =
        estimateProjectorToCamera(capture, options, scene.rig.projectorSize, camera);
    ASSERT_TRUE(estimate.ok()) << estimate.failure().message;
    EXPECT_LT(estimate->rmsPx, 0.1);
    EXPECT_LT(worstCornerError(estimate->homography, scene.rig.projectorToCameraHomography(),
                               projectorChessboardCorners(options, scene.rig.projectorSize)),
              0.1);
}

TEST(ProjectorChessboard, FrameWithoutABoardFailsQuickly) {
    test::SurfaceScene scene;
    scene.rig = test::paperLikeCalibration();
    scene.rectangles.push_back({});  // a card, nothing like a board
    const cv::Mat white(scene.rig.projectorSize, CV_8UC1, cv::Scalar(255));
    const cv::Mat capture = test::renderSurface(scene, white, 2.0);
    const auto start = std::chrono::steady_clock::now();
    const Result<ChessboardDetection> detection =
        detectProjectedChessboard(capture, {}, scene.rig.projectorSize);
    const double elapsedMs =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
    ASSERT_FALSE(detection.ok());
    EXPECT_THAT(detection.failure().message, HasSubstr("no projected chessboard"));
    // Without CALIB_CB_FAST_CHECK the classic finder spends about 7 s on such a frame; with it a few ms (tens
    // under the sanitizers). The bound separates the two on a loaded machine.
    EXPECT_LT(elapsedMs, 500.0);
}

TEST(ProjectorChessboard, RejectsAnImageOfTheWrongType) {
    const cv::Mat floating(488, 648, CV_32FC1, cv::Scalar(0.5));
    EXPECT_THAT(detectProjectedChessboard(floating, {}, {640, 480}).failure().message, HasSubstr("8-bit"));
}

}  // namespace
}  // namespace everytouch::core
