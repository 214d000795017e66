#include "core/calibration.h"

#include <cmath>
#include <limits>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "core/geometry.h"
#include "support/test_rig.h"

namespace everytouch::core {
namespace {

using ::testing::HasSubstr;
using ::testing::Optional;

TEST(Calibration, PaperLikeRigIsValid) {
    EXPECT_EQ(test::paperLikeCalibration().validate(), std::nullopt);
}

TEST(Calibration, ValidateNamesTheFieldAtFault) {
    Calibration calibration = test::paperLikeCalibration();
    calibration.cameraMatrix(0, 0) = -5;
    EXPECT_THAT(calibration.validate(), Optional(HasSubstr("camera_matrix")));

    calibration = test::paperLikeCalibration();
    calibration.tableToProjector.matrix()(0, 1) += 0.1;
    EXPECT_THAT(calibration.validate(), Optional(HasSubstr("table_to_projector")));

    calibration = test::paperLikeCalibration();
    calibration.cameraDistortion(2) = std::numeric_limits<double>::quiet_NaN();
    EXPECT_THAT(calibration.validate(), Optional(HasSubstr("camera_distortion")));

    calibration = test::paperLikeCalibration();
    calibration.displayToProjector.setZero();
    EXPECT_THAT(calibration.validate(), Optional(HasSubstr("display_to_projector")));

    calibration = test::paperLikeCalibration();
    calibration.displaySize = {0, 960};
    EXPECT_THAT(calibration.validate(), Optional(HasSubstr("display_size")));
}

TEST(Calibration, CameraToProjectorFollowsTheTablePoint) {
    const Calibration calibration = test::paperLikeCalibration();
    for (double height : {0.0, 8.0}) {
        const Eigen::Vector3d point(120, 95, height);
        const Eigen::Vector2d camera =
            projectPoint(calibration.cameraMatrix, calibration.tableToCamera, point);
        const Eigen::Vector2d projector =
            projectPoint(calibration.projectorMatrix, calibration.tableToProjector, point);
        EXPECT_LT(
            (applyHomography(calibration.cameraToProjectorHomography(height), camera) - projector).norm(),
            1e-9);
    }
}

TEST(Calibration, ElevatedPlaneSeesAnotherProjectorPixel) {
    // With a baseline of 4 cm, the code under a finger 10 mm above the table comes from a projector pixel
    // about two pixels away from the one the table homography predicts: the parallax touch detection rests
    // on.
    const Calibration calibration = test::paperLikeCalibration();
    const Eigen::Vector2d camera(324, 244);
    const Eigen::Vector2d onTable = applyHomography(calibration.cameraToProjectorHomography(0.0), camera);
    const Eigen::Vector2d raised = applyHomography(calibration.cameraToProjectorHomography(10.0), camera);
    EXPECT_GT((onTable - raised).norm(), 1.0);
}

TEST(Calibration, CameraToDisplayComposesKeystone) {
    const Calibration calibration = test::paperLikeCalibration();
    const Eigen::Vector2d camera(200, 150);
    const Eigen::Vector2d projector = applyHomography(calibration.cameraToProjectorHomography(), camera);
    const Eigen::Vector2d display = applyHomography(calibration.cameraToDisplayHomography(), camera);
    EXPECT_LT((display - 2.0 * projector).norm(), 1e-9);  // the display is twice the panel's resolution
}

TEST(Calibration, APointAboveTheTableMapsToTheDisplayPixelBelowItNotToTheOneLightingIt) {
    const Calibration calibration = test::paperLikeCalibration();
    const Eigen::Vector2d display(300, 200);
    const Eigen::Vector2d onTable = applyHomography(calibration.displayToTableHomography(), display);
    for (const double heightMm : {0.0, 5.0, 35.0}) {
        // The camera's view of the point heightMm straight above where the display pixel lands.
        const Eigen::Vector4d above(onTable.x(), onTable.y(), heightMm, 1.0);
        const Eigen::Vector3d seen =
            calibration.cameraMatrix * (calibration.tableToCamera.matrix() * above).head<3>();
        const Eigen::Vector2d camera = seen.head<2>() / seen.z();
        EXPECT_LT(
            (applyHomography(calibration.cameraToDisplayBelowHomography(heightMm), camera) - display).norm(),
            1e-6)
            << heightMm << " mm";
        // The projector's ray to that point leaves it elsewhere on the display, the more so the higher it is.
        const double apartPx =
            (applyHomography(calibration.cameraToDisplayHomography(heightMm), camera) - display).norm();
        if (heightMm == 0.0)
            EXPECT_LT(apartPx, 1e-6);
        else
            EXPECT_GT(apartPx, 0.1 * heightMm);
    }
}

TEST(Calibration, DisplaySizeIsPhysicalMillimetres) {
    const cv::Size2d size = test::paperLikeCalibration().displaySizeMm();
    // About 500 mm from a 1350 px focal length projector, tilted: a 15" (381 mm) diagonal, give or take
    // keystone.
    EXPECT_NEAR(std::hypot(size.width, size.height), 381.0, 80.0);
}

}  // namespace
}  // namespace everytouch::core
