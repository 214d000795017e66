// The calibration checked against the code the simulated rig's table shows, with the camera where the
// calibration says and knocked away from there.
#include <algorithm>
#include <cmath>
#include <optional>
#include <vector>

#include <opencv2/imgproc.hpp>

#include <gtest/gtest.h>

#include "core/calibration_correction.h"
#include "core/camera_model.h"
#include "core/camera_relocation.h"
#include "core/code_image.h"
#include "core/geometry.h"
#include "core/hand_segmentation.h"
#include "core/registration_check.h"
#include "sim/simulator.h"

namespace everytouch::core {
namespace {

// Pairs of grid35 from frame 60 on (a hand reaches over the table): S and the hand's true mask, with the
// rig's calibration and its true geometry. The rigs of 24 pairs are rendered once for the tests that
// share them.
struct RenderedRig {
    std::vector<cv::Mat> subtractions, handMasks;
    std::vector<std::int64_t> timestampsUs;
    Calibration calibration;  // the rig's, from before any knock
    Calibration real;         // the rig's true geometry over these pairs
    cv::Mat pattern;
    cv::Mat region;  // the segmentation's judged region
};

constexpr int kRenderedPairs = 24;

RenderedRig render(bool knocked, int pairs) {
    sim::SimParameters parameters;
    parameters.scenario = "grid35";
    if (knocked)
        parameters.knockS = 0.0;
    sim::Simulator simulator(parameters, sim::rigPattern(parameters));
    RenderedRig rendered;
    rendered.calibration = simulator.calibration();
    rendered.pattern = simulator.pattern();
    HandSegmenter segmenter{SegmentationOptions{}};
    segmenter.setRig(rendered.calibration, rendered.pattern);
    rendered.region = segmenter.judgedRegion().clone();
    Frame frames[2];
    sim::FrameTruth truth;
    cv::Mat texture;
    const std::uint64_t first = 60;
    for (int i = 0; i < pairs; ++i) {
        for (int k = 0; k < 2; ++k)
            simulator.render(first + 2 * i + k, frames[k], truth);
        computeSubtractionAndTexture(FramePair{frames[0], frames[1]}, rendered.subtractions.emplace_back(),
                                     texture);
        rendered.handMasks.push_back(truth.handMask.clone());
        rendered.timestampsUs.push_back(frames[1].timestampUs);
    }
    rendered.real = simulator.geometryAt(simulator.frameSeconds(first + 2 * pairs));
    return rendered;
}

const RenderedRig& calibratedRig() {
    static const RenderedRig rendered = render(false, kRenderedPairs);
    return rendered;
}

const RenderedRig& knockedRig() {
    static const RenderedRig rendered = render(true, kRenderedPairs);
    return rendered;
}

struct Checked {
    std::optional<double> errorPx;
    std::vector<TileShift> tiles;
    double trueErrorPx = 0.0;  // the median over those tiles of the true misregistration, projector pixels
    double handCover = 0.0;    // the largest share of a tile measured that the hand covered
};

// Runs the check over the first `pairs` pairs, with `calibration` (the rig's when not given).
Checked check(const RenderedRig& rendered, int pairs, const RegistrationOptions& options = {},
              const std::optional<Calibration>& calibration = std::nullopt) {
    const Calibration& used = calibration ? *calibration : rendered.calibration;
    RegistrationCheck registration(options);
    registration.setRig(used, rendered.pattern, rendered.region, 0.5);
    EXPECT_TRUE(registration.hasRig());
    Checked checked;
    for (int i = 0; i < pairs; ++i) {
        const cv::Mat& handMask = rendered.handMasks[i];
        registration.update(rendered.subtractions[i], handMask, rendered.timestampsUs[i]);
        for (const TileShift& tile : registration.latest())
            if (tile.timestampUs == rendered.timestampsUs[i]) {
                const int reach = RegistrationOptions{}.tilePx / 2;
                const cv::Rect window(cv::Point(static_cast<int>(tile.centre.x()) - reach,
                                                static_cast<int>(tile.centre.y()) - reach),
                                      cv::Size(2 * reach, 2 * reach));
                const cv::Rect inside = window & cv::Rect({0, 0}, handMask.size());
                checked.handCover =
                    std::max(checked.handCover, cv::countNonZero(handMask(inside)) / double(inside.area()));
            }
    }
    checked.errorPx = registration.errorPx();
    checked.tiles = registration.latest();

    // What the code really does at each tile: the camera pixel sees the table point the true camera puts
    // there, which the projector lights from its own pixel; the calibration expects another.
    const CameraModel camera{used.cameraMatrix, used.cameraDistortion};
    std::vector<double> trueLengths;
    for (const TileShift& tile : checked.tiles) {
        const Eigen::Vector2d pixel = camera.undistortPixel(tile.centre);
        const Eigen::Vector2d expected = applyHomography(used.cameraToProjectorHomography(), pixel);
        const Eigen::Vector2d seen = applyHomography(rendered.real.cameraToProjectorHomography(), pixel);
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
    const Checked checked = check(calibratedRig(), kRenderedPairs);
    ASSERT_TRUE(checked.errorPx);
    RecordProperty("error_px", std::to_string(*checked.errorPx));
    EXPECT_LT(*checked.errorPx, 0.1);
    for (const TileShift& tile : checked.tiles) {
        EXPECT_LT(tile.projectorPx.norm(), 0.3) << "the tile at " << tile.centre.transpose();
        EXPECT_GT(tile.correlation, 0.3);
    }
}

TEST(RegistrationCheck, AKnockedCameraShowsTheMisregistrationItMade) {
    const Checked checked = check(knockedRig(), kRenderedPairs);
    ASSERT_TRUE(checked.errorPx);
    RecordProperty("error_px", std::to_string(*checked.errorPx));
    RecordProperty("true_error_px", std::to_string(checked.trueErrorPx));
    // Half a degree and 2 mm move the code by several projector pixels on this rig.
    EXPECT_GT(checked.trueErrorPx, 3.0);
    EXPECT_NEAR(*checked.errorPx, checked.trueErrorPx, 0.1 * checked.trueErrorPx);
}

TEST(RegistrationCheck, PassesOverTilesTheHandCovers) {
    const Checked checked = check(calibratedRig(), kRenderedPairs);
    EXPECT_EQ(checked.handCover, 0.0);
}

TEST(RegistrationCheck, SaysNothingBeforeEnoughTilesWereMeasured) {
    RegistrationOptions options;
    options.tilesPerEstimate = 16;
    const Checked checked = check(render(false, 8), 8, options);
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
    const RenderedRig& rig = knockedRig();
    const Checked checked = check(rig, kRenderedPairs);
    const Result<CameraRelocation> relocated = relocateCamera(rig.calibration, checked.tiles);
    ASSERT_TRUE(relocated.ok()) << relocated.failure().message;
    const double turnedDeg = turnDegrees(relocated->tableToCamera, rig.real.tableToCamera);
    const double movedMm = (centreOf(relocated->tableToCamera) - centreOf(rig.real.tableToCamera)).norm();
    RecordProperty("residual_px", std::to_string(relocated->residualPx));
    RecordProperty("turn_left_deg", std::to_string(turnedDeg));
    RecordProperty("shift_left_mm", std::to_string(movedMm));
    EXPECT_LT(relocated->residualPx, 0.2);
    EXPECT_LT(turnedDeg, 0.1);  // of the knock's 0.5
    EXPECT_LT(movedMm, 5.0);

    // The corrected calibration predicts the code where the knocked camera sees it: the check reads a
    // fraction of a pixel again.
    Calibration corrected = rig.calibration;
    corrected.tableToCamera = relocated->tableToCamera;
    const Checked again = check(rig, kRenderedPairs, {}, corrected);
    ASSERT_TRUE(again.errorPx);
    RecordProperty("error_after_px", std::to_string(*again.errorPx));
    EXPECT_LT(*again.errorPx, 0.2);
}

TEST(CameraRelocation, RefusesTooFewTilesOrTilesInOneCorner) {
    const RenderedRig& rig = calibratedRig();
    const Checked checked = check(rig, kRenderedPairs);
    std::vector<TileShift> few(checked.tiles.begin(), checked.tiles.begin() + 5);
    const Result<CameraRelocation> fromFew = relocateCamera(rig.calibration, few);
    ASSERT_FALSE(fromFew.ok());
    EXPECT_NE(fromFew.failure().message.find("5 tiles"), std::string::npos) << fromFew.failure().message;
    std::vector<TileShift> corner(10, checked.tiles.front());
    for (std::size_t i = 0; i < corner.size(); ++i)
        corner[i].centre += Eigen::Vector2d(3.0 * i, 2.0 * i);
    const Result<CameraRelocation> fromCorner = relocateCamera(rig.calibration, corner);
    ASSERT_FALSE(fromCorner.ok());
    EXPECT_NE(fromCorner.failure().message.find("too little of the table"), std::string::npos);
}

// Runs the check and the corrector pair by pair, as the pipeline does, until the corrector corrects.
struct Corrected {
    std::optional<CalibrationCorrection> correction;
    int pair = -1;  // the pair after which it did
    std::string problem;
};

Corrected correct(const RenderedRig& rendered, int pairs) {
    RegistrationCheck registration;
    registration.setRig(rendered.calibration, rendered.pattern, rendered.region, 0.5);
    CalibrationCorrector corrector;
    corrector.setRig(rendered.calibration, RegistrationOptions{}.tilesPerEstimate);
    Corrected corrected;
    for (int i = 0; i < pairs && !corrected.correction; ++i) {
        registration.update(rendered.subtractions[i], rendered.handMasks[i], rendered.timestampsUs[i]);
        corrected.correction = corrector.update(registration.measured(), registration.latest());
        corrected.pair = i;
        corrected.problem = corrector.problem();
    }
    return corrected;
}

TEST(CalibrationCorrector, CorrectsAKnockedCameraAndTheCodeFitsAgain) {
    const RenderedRig& rig = knockedRig();
    const Corrected corrected = correct(rig, kRenderedPairs);
    ASSERT_TRUE(corrected.correction) << corrected.problem;
    const CalibrationCorrection& correction = *corrected.correction;
    RecordProperty("pairs", corrected.pair + 1);
    RecordProperty("before_px", std::to_string(correction.beforePx));
    RecordProperty("after_px", std::to_string(correction.afterPx));
    EXPECT_EQ(corrected.pair + 1, RegistrationOptions{}.tilesPerEstimate);  // the first round decides
    EXPECT_GT(correction.beforePx, 2.0);
    EXPECT_LT(correction.afterPx, 0.2);
    EXPECT_EQ(correction.what, "camera");
    EXPECT_LT(turnDegrees(correction.calibration.tableToCamera, rig.real.tableToCamera), 0.1);
    // Only the camera's pose changed.
    EXPECT_TRUE(correction.calibration.tableToProjector.isApprox(rig.calibration.tableToProjector));
    EXPECT_EQ(correction.calibration.cameraMatrix, rig.calibration.cameraMatrix);
    const Checked again = check(rig, kRenderedPairs, {}, correction.calibration);
    ASSERT_TRUE(again.errorPx);
    EXPECT_LT(*again.errorPx, 0.2);
}

TEST(CalibrationCorrector, LeavesACalibrationThatHoldsAsItIs) {
    const Corrected corrected = correct(calibratedRig(), kRenderedPairs);
    EXPECT_FALSE(corrected.correction);
    EXPECT_EQ(corrected.problem, "");
}

TEST(CalibrationCorrector, RefusesAMisregistrationNoMoveOfTheCameraExplains) {
    const RenderedRig& rig = calibratedRig();
    const Checked checked = check(rig, kRenderedPairs);
    ASSERT_EQ(checked.tiles.size(), 16u);
    // Each tile's code displaced its own way by a pixel: what a warped table or a creeping, distorting
    // projector image could show, and no pose of the camera.
    std::vector<TileShift> scattered = checked.tiles;
    cv::RNG rng(5);
    for (TileShift& tile : scattered)
        tile.cameraPx = Eigen::Vector2d(rng.gaussian(1.5), rng.gaussian(1.5));
    CalibrationCorrector corrector;
    corrector.setRig(rig.calibration, 16);
    EXPECT_FALSE(corrector.update(16, scattered));
    EXPECT_EQ(corrector.problem(), "") << "told after one round";
    EXPECT_FALSE(corrector.update(32, scattered));
    EXPECT_NE(corrector.problem().find(
                  "no move of the camera or of the table or shift of the projector's image explains it"),
              std::string::npos)
        << corrector.problem();
    // Too few tiles for a round: nothing is judged yet.
    CalibrationCorrector waiting;
    waiting.setRig(rig.calibration, 16);
    EXPECT_FALSE(waiting.update(15, scattered));
    EXPECT_EQ(waiting.problem(), "");
}

// `tiles` as they read when the calibration is `believed` and the rig `real`: the code `believed` predicts
// at each tile's centre lights the table point `real` puts it on, and the camera sees that point where both
// say. With `noisePx` camera pixels of noise.
void readTiles(const Calibration& believed, const Calibration& real, double noisePx, cv::RNG& rng,
               std::vector<TileShift>& tiles) {
    const CameraModel camera{believed.cameraMatrix, believed.cameraDistortion};
    const Eigen::Matrix3d realToTable = real.tableToProjectorHomography().inverse();
    for (TileShift& tile : tiles) {
        const Eigen::Vector2d panel =
            applyHomography(believed.cameraToProjectorHomography(), camera.undistortPixel(tile.centre));
        const Eigen::Vector2d lit = applyHomography(realToTable, panel);
        const Eigen::Vector2d seen =
            camera.project(real.tableToCamera * Eigen::Vector3d(lit.x(), lit.y(), 0.0));
        tile.cameraPx = seen - tile.centre + Eigen::Vector2d(rng.gaussian(noisePx), rng.gaussian(noisePx));
    }
}

TEST(CalibrationCorrector, CorrectsACreepingProjectorsImageAsAShiftOnItsPanelAndTheCreepAddsUp) {
    const RenderedRig& rig = calibratedRig();
    std::vector<TileShift> tiles = check(rig, kRenderedPairs).tiles;
    ASSERT_EQ(tiles.size(), 16u);
    CalibrationCorrector corrector;
    corrector.setRig(rig.calibration, 16);
    // The image creeps by 0.6 px a round (its principal point moves, as the simulator's drift moves it),
    // each round read against the correction before, with a twentieth of a camera pixel of noise: twenty
    // rounds of it (12 px, six minutes at 2 px a minute).
    const Eigen::Vector2d step(0.5, -0.33);
    Calibration believed = rig.calibration, real = rig.calibration;
    cv::RNG rng(11);
    int corrections = 0, ofTheImage = 0;
    for (int round = 1; round <= 20; ++round) {
        real.projectorMatrix(0, 2) += step.x();
        real.projectorMatrix(1, 2) += step.y();
        readTiles(believed, real, 0.05, rng, tiles);
        const std::optional<CalibrationCorrection> correction = corrector.update(16 * round, tiles);
        if (!correction)
            continue;
        ++corrections;
        EXPECT_LT(correction->afterPx, 0.1) << "round " << round;
        if (correction->what == "projector") {
            ++ofTheImage;
            // Nothing else changed.
            EXPECT_TRUE(correction->calibration.tableToCamera.isApprox(believed.tableToCamera));
            EXPECT_TRUE(correction->calibration.tableToProjector.isApprox(believed.tableToProjector));
        }
        believed = correction->calibration;
    }
    EXPECT_GE(corrections, 15);
    EXPECT_EQ(ofTheImage, corrections);
    // The last correction left the code where the calibration predicts it, over the whole table.
    readTiles(believed, real, 0.0, rng, tiles);
    double squares = 0.0;
    for (const TileShift& tile : tiles)
        squares += tile.cameraPx.squaredNorm();
    EXPECT_LT(std::sqrt(squares / static_cast<double>(tiles.size())), 0.1);
    EXPECT_EQ(corrector.problem(), "");
}

// The table tilted by `degrees` about a level axis at `axisAngle` through `centre` (table mm), as the
// simulator's table_tilt tilts it: the rig stands against the table's new frame.
Calibration tilted(const Calibration& calibration, double degrees, double axisAngle,
                   const Eigen::Vector3d& centre) {
    Eigen::Isometry3d tilt = Eigen::Isometry3d::Identity();
    tilt.linear() = Eigen::AngleAxisd(degrees * M_PI / 180.0,
                                      Eigen::Vector3d(std::cos(axisAngle), std::sin(axisAngle), 0.0))
                        .toRotationMatrix();
    tilt.translation() = centre - tilt.linear() * centre;
    Calibration real = calibration;
    real.tableToCamera = calibration.tableToCamera * tilt;
    real.tableToProjector = calibration.tableToProjector * tilt;
    return real;
}

// The table's normal in the camera's frame.
Eigen::Vector3d tableNormal(const Calibration& calibration) {
    return calibration.tableToCamera.linear() * Eigen::Vector3d::UnitZ();
}

TEST(CalibrationCorrector, CorrectsATiltedTableAsItsPlaneAndTheCodeFitsAgain) {
    const RenderedRig& rig = calibratedRig();
    std::vector<TileShift> tiles = check(rig, kRenderedPairs).tiles;
    ASSERT_EQ(tiles.size(), 16u);
    const Eigen::Vector2d middle = rig.calibration.displayCentreOnTable();
    // A leg on a cable: 2, 4 and 6 degrees about axes through the display's centre and 100 mm beside it,
    // each with a twentieth of a camera pixel of noise.
    cv::RNG rng(3);
    for (const double degrees : {2.0, 4.0, 6.0})
        for (const Eigen::Vector3d& centre : {Eigen::Vector3d(middle.x(), middle.y(), 0.0),
                                              Eigen::Vector3d(middle.x() + 100.0, middle.y(), 0.0)}) {
            SCOPED_TRACE(std::to_string(degrees) + " degrees about x = " + std::to_string(centre.x()));
            const Calibration real = tilted(rig.calibration, degrees, 0.7, centre);
            readTiles(rig.calibration, real, 0.05, rng, tiles);
            CalibrationCorrector corrector;
            corrector.setRig(rig.calibration, 16);
            const std::optional<CalibrationCorrection> correction = corrector.update(16, tiles);
            ASSERT_TRUE(correction) << corrector.problem();
            EXPECT_EQ(correction->what, "table");
            EXPECT_LT(correction->afterPx, 0.1);
            // The plane found is the table's, as far as 16 tiles with that noise tell it (0.15-0.21 degrees
            // off here, under 0.02 without the noise), and neither device moved against the other.
            const double normalErrorDeg =
                std::acos(std::min(1.0, tableNormal(correction->calibration).dot(tableNormal(real)))) *
                180.0 / M_PI;
            EXPECT_LT(normalErrorDeg, 0.3);
            const Eigen::Isometry3d pairBefore =
                rig.calibration.tableToProjector * rig.calibration.tableToCamera.inverse();
            const Eigen::Isometry3d pairAfter =
                correction->calibration.tableToProjector * correction->calibration.tableToCamera.inverse();
            EXPECT_TRUE(pairAfter.isApprox(pairBefore, 1e-9));
            // The code lies where the corrected calibration predicts it over the whole table.
            readTiles(correction->calibration, real, 0.0, rng, tiles);
            double squares = 0.0;
            for (const TileShift& tile : tiles)
                squares += tile.cameraPx.squaredNorm();
            EXPECT_LT(std::sqrt(squares / static_cast<double>(tiles.size())), 0.05);
        }
}

TEST(CalibrationCorrector, WatchesWithoutAProblemWhatAMoveExplainsButNotYetBeyondTheNoise) {
    const RenderedRig& rig = calibratedRig();
    const Checked checked = check(rig, kRenderedPairs);
    ASSERT_EQ(checked.tiles.size(), 16u);
    // The code a third of a pixel off as one small move of the camera would put it (a projector's image that
    // crept a few seconds), read with a tenth of a pixel of noise: a move explains most of it, but not yet
    // three times the noise, and what it leaves is within what a calibration may be off by.
    std::vector<TileShift> crept = checked.tiles;
    cv::RNG rng(7);
    for (TileShift& tile : crept)
        tile.cameraPx = Eigen::Vector2d(0.3 + rng.gaussian(0.1), rng.gaussian(0.1));
    CalibrationCorrector corrector;
    corrector.setRig(rig.calibration, 16);
    for (int round = 1; round <= 3; ++round) {
        EXPECT_FALSE(corrector.update(16 * round, crept)) << "round " << round;
        EXPECT_EQ(corrector.problem(), "") << "round " << round;
    }
}

TEST(CorrectionOptions, ValidateNamesTheField) {
    CorrectionOptions options;
    EXPECT_FALSE(options.validate());
    options.leastErrorPx = 0.0;
    ASSERT_TRUE(options.validate());
    EXPECT_NE(options.validate()->find("leastErrorPx"), std::string::npos);
    EXPECT_THROW(CalibrationCorrector{options}, std::invalid_argument);
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
