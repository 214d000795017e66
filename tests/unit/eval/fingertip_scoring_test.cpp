#include "eval/fingertip_scoring.h"

#include <gtest/gtest.h>

#include "core/camera_model.h"
#include "core/geometry.h"
#include "support/test_rig.h"

namespace everytouch::eval {
namespace {

TruthPoint point(double x, double y, double widthPx = 20.0) {
    TruthPoint truth;
    truth.camera = {x, y};
    truth.fingerWidthPx = widthPx;
    return truth;
}

TEST(MatchFingertips, MatchesEachTruthToItsNearestDetectionOnce) {
    const std::vector<TruthPoint> truth{point(100, 100), point(130, 100)};
    const std::vector<Eigen::Vector2d> detections{{128, 103}, {104, 97}, {300, 300}};
    const std::vector<FingertipMatch> matches = matchFingertips(truth, detections);
    ASSERT_EQ(matches.size(), 2u);
    EXPECT_EQ(matches[0].truth, 1u);
    EXPECT_EQ(matches[0].detection, 0u);
    EXPECT_NEAR(matches[0].errorPx, std::hypot(2.0, 3.0), 1e-12);
    EXPECT_EQ(matches[1].truth, 0u);
    EXPECT_EQ(matches[1].detection, 1u);
    EXPECT_NEAR(matches[1].errorPx, 5.0, 1e-12);
}

TEST(MatchFingertips, ADetectionServesOneFingerOnly) {
    // Two fingers side by side, one tip found between them: the nearer finger gets it.
    const std::vector<TruthPoint> truth{point(100, 100), point(118, 100)};
    const std::vector<FingertipMatch> matches = matchFingertips(truth, {{110, 100}});
    ASSERT_EQ(matches.size(), 1u);
    EXPECT_EQ(matches[0].truth, 1u);
}

TEST(MatchFingertips, NothingBeyondAFingerWidth) {
    const std::vector<TruthPoint> truth{point(100, 100, 20.0)};
    EXPECT_TRUE(matchFingertips(truth, {{121, 100}}).empty());
    EXPECT_EQ(matchFingertips(truth, {{119, 100}}).size(), 1u);
    EXPECT_TRUE(matchFingertips({}, {{1, 1}}).empty());
    EXPECT_TRUE(matchFingertips(truth, {}).empty());
}

TEST(FingertipScore, RatesErrorsAndUnmatchedDetections) {
    FingertipScore score;
    EXPECT_FALSE(score.detectionRate());
    EXPECT_FALSE(score.meanErrorPx());
    score.add(2, 3, {{0, 0, 2.0}, {1, 2, 4.0}});
    score.add(1, 0, {});
    score.add(0, 1, {});
    EXPECT_EQ(score.truth(), 3);
    EXPECT_EQ(score.matched(), 2);
    EXPECT_NEAR(*score.detectionRate(), 2.0 / 3.0, 1e-12);
    EXPECT_NEAR(*score.meanErrorPx(), 3.0, 1e-12);
    EXPECT_NEAR(*score.unmatchedPerPair(), 2.0 / 3.0, 1e-12);
}

TEST(TruthToCamera, PutsThePadAboveItsContactPointAtItsHeight) {
    const core::Calibration calibration = test::distortedPaperLikeCalibration();
    const TruthToCamera toCamera(calibration, 16.0);
    const core::CameraModel camera{calibration.cameraMatrix, calibration.cameraDistortion};
    const Eigen::Matrix3d displayToTable = calibration.displayToTableHomography();
    for (double height : {0.0, 8.0, 30.0}) {
        core::FingerTruth finger;
        finger.id = 6;
        finger.x = 400;
        finger.y = 700;
        finger.heightMm = height;
        const Eigen::Vector2d table = core::applyHomography(displayToTable, {finger.x, finger.y});
        const Eigen::Vector3d pad(table.x(), table.y(), height);
        const Eigen::Vector2d expected = camera.project(calibration.tableToCamera * pad);
        const TruthPoint point = toCamera(finger);
        EXPECT_EQ(point.id, 6u);
        EXPECT_LT((point.camera - expected).norm(), 1e-6) << "height " << height;
    }
}

TEST(TruthToCamera, FingerWidthFollowsTheCameraScale) {
    const core::Calibration calibration = test::paperLikeCalibration();
    const TruthToCamera toCamera(calibration, 16.0);
    // 1.1 to 1.6 camera pixels per mm on the paper's rig (f = 811 px at 500 to 700 mm).
    const double widthPx = toCamera.fingerWidthPxAtCentre();
    EXPECT_GT(widthPx, 16.0 * 1.1);
    EXPECT_LT(widthPx, 16.0 * 1.6);
    // A finger 40 mm up is nearer to the camera: wider in the image.
    core::FingerTruth finger;
    finger.x = calibration.displaySize.width / 2.0;
    finger.y = calibration.displaySize.height / 2.0;
    const double onTable = toCamera(finger).fingerWidthPx;
    EXPECT_NEAR(onTable, widthPx, 1e-9);
    finger.heightMm = 40.0;
    EXPECT_GT(toCamera(finger).fingerWidthPx, onTable * 1.05);
    EXPECT_NEAR(TruthToCamera(calibration, 8.0).fingerWidthPxAtCentre(), widthPx / 2.0, widthPx * 1e-3);
}

}  // namespace
}  // namespace everytouch::eval
