// The calibration checked against the code the simulated rig's table shows, with the camera where the
// calibration says and knocked away from there.
#include <algorithm>
#include <cmath>
#include <optional>
#include <vector>

#include <opencv2/imgproc.hpp>

#include <gtest/gtest.h>

#include "core/camera_model.h"
#include "core/camera_relocation.h"
#include "core/code_image.h"
#include "core/geometry.h"
#include "core/hand_segmentation.h"
#include "core/registration_check.h"
#include "sim/simulator.h"

namespace everytouch::core {
namespace {

struct Checked {
    std::optional<double> errorPx;
    std::vector<TileShift> tiles;
    double trueErrorPx = 0.0;  // the median over those tiles of the true misregistration, projector pixels
    double handCover = 0.0;    // the largest share of a tile measured that the hand covered
    Calibration calibration;   // the rig's, from before any knock
    Calibration real;          // the rig's true geometry at the last pair
    cv::Mat pattern;
    cv::Mat region;
};

// Runs the check over `pairs` pairs of grid35 from frame 60 on (a hand reaches over the table), with the
// hand's true mask.
Checked check(sim::SimParameters parameters, int pairs, const RegistrationOptions& options = {}) {
    parameters.scenario = "grid35";
    sim::Simulator simulator(parameters, sim::rigPattern(parameters));
    const Calibration& calibration = simulator.calibration();
    HandSegmenter segmenter{SegmentationOptions{}};
    segmenter.setRig(calibration, simulator.pattern());
    RegistrationCheck registration(options);
    registration.setRig(calibration, simulator.pattern(), segmenter.judgedRegion(), 0.5);
    EXPECT_TRUE(registration.hasRig());

    Checked checked;
    Frame frames[2];
    sim::FrameTruth truth;
    cv::Mat subtraction, texture;
    const std::uint64_t first = 60;
    for (int i = 0; i < pairs; ++i) {
        for (int k = 0; k < 2; ++k)
            simulator.render(first + 2 * i + k, frames[k], truth);
        computeSubtractionAndTexture(FramePair{frames[0], frames[1]}, subtraction, texture);
        registration.update(subtraction, truth.handMask, frames[1].timestampUs);
        for (const TileShift& tile : registration.latest())
            if (tile.timestampUs == frames[1].timestampUs) {
                const int reach = RegistrationOptions{}.tilePx / 2;
                const cv::Rect window(cv::Point(static_cast<int>(tile.centre.x()) - reach,
                                                static_cast<int>(tile.centre.y()) - reach),
                                      cv::Size(2 * reach, 2 * reach));
                const cv::Rect inside = window & cv::Rect({0, 0}, truth.handMask.size());
                checked.handCover = std::max(
                    checked.handCover, cv::countNonZero(truth.handMask(inside)) / double(inside.area()));
            }
    }
    checked.errorPx = registration.errorPx();
    checked.tiles = registration.latest();

    // What the code really does at each tile: the camera pixel sees the table point the true camera puts
    // there, which the projector lights from its own pixel; the calibration expects another.
    const Calibration real = simulator.geometryAt(simulator.frameSeconds(first + 2 * pairs));
    checked.calibration = calibration;
    checked.real = real;
    checked.pattern = simulator.pattern();
    checked.region = segmenter.judgedRegion().clone();
    const CameraModel camera{calibration.cameraMatrix, calibration.cameraDistortion};
    std::vector<double> trueLengths;
    for (const TileShift& tile : checked.tiles) {
        const Eigen::Vector2d pixel = camera.undistortPixel(tile.centre);
        const Eigen::Vector2d expected = applyHomography(calibration.cameraToProjectorHomography(), pixel);
        const Eigen::Vector2d seen = applyHomography(real.cameraToProjectorHomography(), pixel);
        trueLengths.push_back((seen - expected).norm());
    }
    if (!trueLengths.empty()) {
        std::nth_element(trueLengths.begin(), trueLengths.begin() + trueLengths.size() / 2,
                         trueLengths.end());
        checked.trueErrorPx = trueLengths[trueLengths.size() / 2];
    }
    return checked;
}

TEST(RegistrationCheck, ACalibrationThatHoldsShowsAFewHundredthsOfAPixel) {
    const Checked checked = check(sim::SimParameters{}, 24);
    ASSERT_TRUE(checked.errorPx);
    RecordProperty("error_px", std::to_string(*checked.errorPx));
    EXPECT_LT(*checked.errorPx, 0.1);
    for (const TileShift& tile : checked.tiles) {
        EXPECT_LT(tile.projectorPx.norm(), 0.3) << "the tile at " << tile.centre.transpose();
        EXPECT_GT(tile.correlation, 0.3);
    }
}

TEST(RegistrationCheck, AKnockedCameraShowsTheMisregistrationItMade) {
    sim::SimParameters parameters;
    parameters.knockS = 0.0;
    const Checked checked = check(parameters, 24);
    ASSERT_TRUE(checked.errorPx);
    RecordProperty("error_px", std::to_string(*checked.errorPx));
    RecordProperty("true_error_px", std::to_string(checked.trueErrorPx));
    // Half a degree and 2 mm move the code by several projector pixels on this rig.
    EXPECT_GT(checked.trueErrorPx, 3.0);
    EXPECT_NEAR(*checked.errorPx, checked.trueErrorPx, 0.1 * checked.trueErrorPx);
}

TEST(RegistrationCheck, PassesOverTilesTheHandCovers) {
    const Checked checked = check(sim::SimParameters{}, 24);
    EXPECT_EQ(checked.handCover, 0.0);
}

TEST(RegistrationCheck, SaysNothingBeforeEnoughTilesWereMeasured) {
    RegistrationOptions options;
    options.tilesPerEstimate = 16;
    const Checked checked = check(sim::SimParameters{}, 8, options);
    EXPECT_FALSE(checked.errorPx);
    EXPECT_LE(checked.tiles.size(), 8u);
}

double turnDegrees(const Eigen::Isometry3d& a, const Eigen::Isometry3d& b) {
    return Eigen::AngleAxisd(a.linear() * b.linear().transpose()).angle() * 180.0 / M_PI;
}

Eigen::Vector3d centreOf(const Eigen::Isometry3d& tableToDevice) {
    return -(tableToDevice.linear().transpose() * tableToDevice.translation());
}

TEST(CameraRelocation, FindsWhereTheKnockPutTheCameraAndTheCodeFitsAgain) {
    sim::SimParameters parameters;
    parameters.knockS = 0.0;
    const Checked checked = check(parameters, 24);
    const Result<CameraRelocation> relocated = relocateCamera(checked.calibration, checked.tiles);
    ASSERT_TRUE(relocated.ok()) << relocated.failure().message;
    const double turnedDeg = turnDegrees(relocated->tableToCamera, checked.real.tableToCamera);
    const double movedMm = (centreOf(relocated->tableToCamera) - centreOf(checked.real.tableToCamera)).norm();
    RecordProperty("residual_px", std::to_string(relocated->residualPx));
    RecordProperty("turn_left_deg", std::to_string(turnedDeg));
    RecordProperty("shift_left_mm", std::to_string(movedMm));
    EXPECT_LT(relocated->residualPx, 0.2);
    EXPECT_LT(turnedDeg, 0.1);  // of the knock's 0.5
    EXPECT_LT(movedMm, 5.0);

    // The corrected calibration predicts the code where the knocked camera sees it: the check reads a
    // fraction of a pixel again.
    Calibration corrected = checked.calibration;
    corrected.tableToCamera = relocated->tableToCamera;
    RegistrationCheck registration;
    registration.setRig(corrected, checked.pattern, checked.region, 0.5);
    sim::Simulator simulator(parameters, sim::rigPattern(parameters));
    Frame frames[2];
    sim::FrameTruth truth;
    cv::Mat subtraction, texture;
    for (int i = 0; i < 24; ++i) {
        for (int k = 0; k < 2; ++k)
            simulator.render(60 + 2 * i + k, frames[k], truth);
        computeSubtractionAndTexture(FramePair{frames[0], frames[1]}, subtraction, texture);
        registration.update(subtraction, truth.handMask, frames[1].timestampUs);
    }
    ASSERT_TRUE(registration.errorPx());
    RecordProperty("error_after_px", std::to_string(*registration.errorPx()));
    EXPECT_LT(*registration.errorPx(), 0.2);
}

TEST(CameraRelocation, RefusesTooFewTilesOrTilesInOneCorner) {
    const Checked checked = check(sim::SimParameters{}, 24);
    std::vector<TileShift> few(checked.tiles.begin(), checked.tiles.begin() + 5);
    const Result<CameraRelocation> fromFew = relocateCamera(checked.calibration, few);
    ASSERT_FALSE(fromFew.ok());
    EXPECT_NE(fromFew.failure().message.find("5 tiles"), std::string::npos) << fromFew.failure().message;
    std::vector<TileShift> corner(10, checked.tiles.front());
    for (std::size_t i = 0; i < corner.size(); ++i)
        corner[i].centre += Eigen::Vector2d(3.0 * i, 2.0 * i);
    const Result<CameraRelocation> fromCorner = relocateCamera(checked.calibration, corner);
    ASSERT_FALSE(fromCorner.ok());
    EXPECT_NE(fromCorner.failure().message.find("too little of the table"), std::string::npos);
}

TEST(RegistrationOptions, ValidateNamesTheField) {
    RegistrationOptions options;
    EXPECT_FALSE(options.validate());
    options.searchMm = 0.0;
    ASSERT_TRUE(options.validate());
    EXPECT_NE(options.validate()->find("searchMm"), std::string::npos);
    options = {};
    options.triesPerPair = 0;
    ASSERT_TRUE(options.validate());
    EXPECT_NE(options.validate()->find("tilesPerPair"), std::string::npos);
}

}  // namespace
}  // namespace everytouch::core
