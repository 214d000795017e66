#include "core/pair_calibration.h"

#include <algorithm>
#include <chrono>
#include <stdexcept>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "core/geometry.h"
#include "core/table_setup.h"
#include "support/plane_view_capture.h"
#include "support/test_rig.h"

namespace everytouch::core {
namespace {

using ::testing::HasSubstr;

using test::calibrationPoses;

// The stripe centred in the lit part of a surface, along its x axis.
test::DarkRectangle stripeInTheLight(const Calibration& surfaceRig) {
    const Eigen::Vector2d lit =
        applyHomography(surfaceRig.tableToProjectorHomography().inverse(), {320, 240});
    test::DarkRectangle stripe;
    stripe.originMm = lit - Eigen::Vector2d(85.5, 12.5) / 2.0;
    return stripe;
}

// A board of 40 px squares: smaller than the default so that it stays in the camera's view on every tilt.
ChessboardOptions calibrationBoard() {
    ChessboardOptions options;
    options.squarePx = 40;
    return options;
}

PairCalibrationOptions optionsFor(const Calibration& rig) {
    PairCalibrationOptions options;
    options.cameraSize = rig.cameraSize;
    options.projectorSize = rig.projectorSize;
    return options;
}

// The projector pixel that lights what the camera sees at a raw pixel, on a plane `heightMm` above the table:
// the map touch detection relies on.
Eigen::Vector2d projectorPixelSeenAt(const Calibration& calibration, const Eigen::Vector2d& rawCameraPixel,
                                     double heightMm) {
    const CameraModel camera{calibration.cameraMatrix, calibration.cameraDistortion};
    return applyHomography(calibration.cameraToProjectorHomography(heightMm),
                           camera.undistortPixel(rawCameraPixel));
}

// Exact correspondences on a grid of projector pixels and the exact stripe corners, raw camera pixels.
PlaneView exactView(const Calibration& surface, bool withStripe) {
    const CameraModel camera{surface.cameraMatrix, surface.cameraDistortion};
    const auto seen = [&](const Eigen::Vector2d& mm) {
        return camera.project(surface.tableToCamera * Eigen::Vector3d(mm.x(), mm.y(), 0));
    };
    PlaneView view;
    for (double x = 100; x <= 540; x += 55) {
        for (double y = 100; y <= 380; y += 55) {
            view.projectorPoints.emplace_back(x, y);
            view.cameraPoints.push_back(
                seen(applyHomography(surface.tableToProjectorHomography().inverse(), {x, y})));
        }
    }
    if (withStripe) {
        const test::DarkRectangle stripe = stripeInTheLight(surface);
        view.rectangleCorners = {seen(stripe.originMm), seen(stripe.originMm + Eigen::Vector2d(85.5, 0)),
                                 seen(stripe.originMm + Eigen::Vector2d(85.5, 12.5)),
                                 seen(stripe.originMm + Eigen::Vector2d(0, 12.5))};
    }
    return view;
}

TEST(PairCalibration, ExactCorrespondencesGiveTheExactPair) {
    const Calibration rig = test::distortedPaperLikeCalibration();
    const ProjectorCameraPair truth = pairOf(rig);
    std::vector<PlaneView> views;
    for (const Eigen::Isometry3d& pose : calibrationPoses())
        views.push_back(exactView(test::onSurface(rig, pose), true));
    const Result<PairCalibration> calibration = calibrateProjectorCameraPair(views, optionsFor(rig));
    ASSERT_TRUE(calibration.ok()) << calibration.failure().message;
    EXPECT_LT(calibration->rmsPx.all, 1e-6);
    EXPECT_TRUE(calibration->pair.camera.matrix.isApprox(truth.camera.matrix, 1e-8));
    EXPECT_TRUE(calibration->pair.camera.distortion.isApprox(truth.camera.distortion, 1e-6));
    EXPECT_TRUE(calibration->pair.projectorMatrix.isApprox(truth.projectorMatrix, 1e-8));
    EXPECT_TRUE(calibration->pair.cameraToProjector.isApprox(truth.cameraToProjector, 1e-8));
    ASSERT_EQ(calibration->planes.size(), views.size());
    // The table's distance from the camera: the scale the rectangle gives.
    EXPECT_NEAR(calibration->planes[0].absDistance(Eigen::Vector3d::Zero()),
                std::abs(rig.tableToCamera.translation().dot(rig.tableToCamera.rotation().col(2))), 1e-6);
}

TEST(PairCalibration, DenseCorrespondencesAreThinnedAndViewsWithoutTheRectangleJoinIn) {
    const Calibration rig = test::distortedPaperLikeCalibration();
    std::vector<PlaneView> views;
    for (const Eigen::Isometry3d& pose : calibrationPoses())
        views.push_back(exactView(test::onSurface(rig, pose), views.size() < 4));
    PairCalibrationOptions options = optionsFor(rig);
    options.maxPointsPerView = 20;  // of 54
    const Result<PairCalibration> calibration = calibrateProjectorCameraPair(views, options);
    ASSERT_TRUE(calibration.ok()) << calibration.failure().message;
    EXPECT_TRUE(calibration->pair.cameraToProjector.isApprox(pairOf(rig).cameraToProjector, 1e-8));
    // The plane of a view without rectangle is found from its correspondences alone.
    const Calibration last = test::onSurface(rig, calibrationPoses().back());
    EXPECT_NEAR(calibration->planes.back().absDistance(Eigen::Vector3d::Zero()),
                std::abs(last.tableToCamera.translation().dot(last.tableToCamera.rotation().col(2))), 1e-6);
}

TEST(PairCalibration, NeedsTheRectangleOnThreeSurfaces) {
    const Calibration rig = test::distortedPaperLikeCalibration();
    std::vector<PlaneView> views;
    for (const Eigen::Isometry3d& pose : calibrationPoses())
        views.push_back(exactView(test::onSurface(rig, pose), views.size() < 2));
    const Result<PairCalibration> calibration = calibrateProjectorCameraPair(views, optionsFor(rig));
    ASSERT_FALSE(calibration.ok());
    EXPECT_THAT(calibration.failure().message, HasSubstr("lies on 2 of the views"));
}

TEST(PairCalibration, OptionsThatDoNotValidateAreAProgrammingError) {
    const Calibration rig = test::distortedPaperLikeCalibration();
    std::vector<PlaneView> views;
    for (const Eigen::Isometry3d& pose : calibrationPoses())
        views.push_back(exactView(test::onSurface(rig, pose), true));
    PairCalibrationOptions options = optionsFor(rig);
    options.maxRmsPx = 0.0;
    EXPECT_THROW((void)calibrateProjectorCameraPair(views, options), std::invalid_argument);
}

TEST(PairCalibration, RectanglesOnParallelSurfacesAreNotEnough) {
    // The board only lifted, never tilted: every view sees the same directions.
    const Calibration rig = test::distortedPaperLikeCalibration();
    std::vector<PlaneView> views;
    for (double liftMm : {0.0, 30.0, 60.0, 90.0})
        views.push_back(exactView(test::onSurface(rig, test::tiltedBoard(0, 0, liftMm)), true));
    const Result<PairCalibration> calibration = calibrateProjectorCameraPair(views, optionsFor(rig));
    ASSERT_FALSE(calibration.ok());
    EXPECT_THAT(calibration.failure().message, HasSubstr("differ in tilt by 0.0 degrees"));
}

TEST(PairCalibration, WrongCorrespondencesFailOnTheReprojectionError) {
    const Calibration rig = test::distortedPaperLikeCalibration();
    std::vector<PlaneView> views;
    for (const Eigen::Isometry3d& pose : calibrationPoses())
        views.push_back(exactView(test::onSurface(rig, pose), true));
    // One view's board read with its rows upside down.
    std::reverse(views[2].projectorPoints.begin(), views[2].projectorPoints.end());
    const Result<PairCalibration> calibration = calibrateProjectorCameraPair(views, optionsFor(rig));
    ASSERT_FALSE(calibration.ok());
    EXPECT_THAT(calibration.failure().message, HasSubstr("RMS reprojection error"));
}

struct RenderedCase {
    double noiseSigmaDn;
    double maxRmsPx;
};

class RenderedPoses : public ::testing::TestWithParam<RenderedCase> {};

// Six poses (the table and five tilts of a plain board), each seen twice: the projected chessboard, and the
// stripe lying on the surface under white light. Rendered through the distorted rig, found by the detectors,
// calibrated.
TEST_P(RenderedPoses, RecoverThePairAndTheMapsTouchDetectionUses) {
    const RenderedCase scenario = GetParam();
    const Calibration rig = test::distortedPaperLikeCalibration();
    const ProjectorCameraPair truth = pairOf(rig);
    std::vector<PlaneView> views;
    unsigned seed = 10;
    for (const Eigen::Isometry3d& pose : calibrationPoses()) {
        const Calibration surface = test::onSurface(rig, pose);
        const Result<PlaneView> captured = test::captureView(
            surface, stripeInTheLight(surface), scenario.noiseSigmaDn, seed += 2, {}, calibrationBoard());
        ASSERT_TRUE(captured.ok()) << captured.failure().message;
        views.push_back(captured.value());
    }
    const auto start = std::chrono::steady_clock::now();
    const Result<PairCalibration> calibration = calibrateProjectorCameraPair(views, optionsFor(rig));
    const double elapsedMs =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
    ASSERT_TRUE(calibration.ok()) << calibration.failure().message;
    const ProjectorCameraPair& found = calibration->pair;
    const PairUncertainty& sigma = calibration->standardDeviation;

    const double rotationErrorDeg =
        Eigen::AngleAxisd(found.cameraToProjector.rotation().transpose() * truth.cameraToProjector.rotation())
            .angle() *
        180.0 / M_PI;
    const double translationErrorMm =
        (found.cameraToProjector.translation() - truth.cameraToProjector.translation()).norm();
    RecordProperty("rms_px", std::to_string(calibration->rmsPx.all));
    RecordProperty("camera_focal_error_px",
                   std::to_string(found.camera.matrix(0, 0) - truth.camera.matrix(0, 0)));
    RecordProperty("camera_centre_error_px",
                   std::to_string((found.camera.matrix.col(2) - truth.camera.matrix.col(2)).norm()));
    RecordProperty("projector_focal_error_px",
                   std::to_string(found.projectorMatrix(0, 0) - truth.projectorMatrix(0, 0)));
    RecordProperty("projector_centre_error_px",
                   std::to_string((found.projectorMatrix.col(2) - truth.projectorMatrix.col(2)).norm()));
    RecordProperty("k1_error", std::to_string(found.camera.distortion(0) - truth.camera.distortion(0)));
    RecordProperty("k2_error", std::to_string(found.camera.distortion(1) - truth.camera.distortion(1)));
    RecordProperty("rotation_error_deg", std::to_string(rotationErrorDeg));
    RecordProperty("translation_error_mm", std::to_string(translationErrorMm));
    RecordProperty("sigma_camera_focal_px", std::to_string(sigma.camera(0)));
    RecordProperty("sigma_camera_centre_px", std::to_string(sigma.camera.tail<2>().norm()));
    RecordProperty("sigma_projector_focal_px", std::to_string(sigma.projector(0)));
    RecordProperty("sigma_projector_centre_px", std::to_string(sigma.projector.tail<2>().norm()));
    RecordProperty("elapsed_ms", std::to_string(elapsedMs));

    EXPECT_LT(calibration->rmsPx.all, scenario.maxRmsPx);
    // The rectangle is the only metric information and it is small (about 140 x 16 camera pixels), so the
    // intrinsics are the least certain part: a focal length to about 0.5 % (1 sigma about 2-4 px), a
    // principal point to several pixels. The tolerances are about four of the estimator's own standard
    // deviations.
    EXPECT_NEAR(found.camera.matrix(0, 0), truth.camera.matrix(0, 0), 0.01 * truth.camera.matrix(0, 0));
    EXPECT_NEAR(found.projectorMatrix(0, 0), truth.projectorMatrix(0, 0), 0.01 * truth.projectorMatrix(0, 0));
    EXPECT_LT((found.camera.matrix.col(2) - truth.camera.matrix.col(2)).norm(), 15.0);
    EXPECT_LT((found.projectorMatrix.col(2) - truth.projectorMatrix.col(2)).norm(), 20.0);
    EXPECT_NEAR(found.camera.distortion(0), truth.camera.distortion(0), 0.03);
    EXPECT_LT(rotationErrorDeg, 0.2);
    EXPECT_LT(translationErrorMm, 1.0);

    // What matters downstream: after the quick set-up on the table with the recovered pair, the camera pixel
    // -> projector pixel map at the table and above it agrees with the truth across the lit area.
    const Calibration table = test::onSurface(rig, Eigen::Isometry3d::Identity());
    const Result<PlaneView> tableView =
        test::captureView(table, stripeInTheLight(table), scenario.noiseSigmaDn, 3, found.camera);
    ASSERT_TRUE(tableView.ok()) << tableView.failure().message;
    const Result<TableSetup> setup = setUpTable(found, tableView.value(), {});
    ASSERT_TRUE(setup.ok()) << setup.failure().message;
    RecordProperty("table_setup_rms_px", std::to_string(setup->rmsPx.all));
    EXPECT_LT(setup->rmsPx.all, scenario.maxRmsPx);
    const Eigen::Isometry3d rectangleToTable =
        Eigen::Translation3d(stripeInTheLight(table).originMm.x(), stripeInTheLight(table).originMm.y(), 0) *
        Eigen::Isometry3d::Identity();
    Calibration truthInRectangleFrame = rig;
    truthInRectangleFrame.tableToCamera = rig.tableToCamera * rectangleToTable;
    truthInRectangleFrame.tableToProjector = rig.tableToProjector * rectangleToTable;
    double worstPx = 0;
    for (double heightMm : {0.0, 10.0, 40.0}) {
        for (double x = 150; x <= 500; x += 50) {
            for (double y = 20; y <= 230; y += 30) {
                const Eigen::Vector2d expected =
                    projectorPixelSeenAt(truthInRectangleFrame, {x, y}, heightMm);
                worstPx = std::max(
                    worstPx, (projectorPixelSeenAt(setup->calibration, {x, y}, heightMm) - expected).norm());
            }
        }
    }
    RecordProperty("worst_camera_to_projector_error_px", std::to_string(worstPx));
    EXPECT_LT(worstPx, 0.5);
}

INSTANTIATE_TEST_SUITE_P(NoiseFreeAndNoisy, RenderedPoses,
                         ::testing::Values(RenderedCase{0.0, 0.1}, RenderedCase{2.0, 0.5}),
                         [](const auto& info) {
                             return info.param.noiseSigmaDn > 0 ? "Noisy" : "NoiseFree";
                         });

}  // namespace
}  // namespace everytouch::core
