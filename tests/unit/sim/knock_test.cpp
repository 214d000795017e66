// The simulated rig moving after its calibration (a knocked camera, a creeping projector image, a table that
// slid or tilted): what moves and what stays.
#include <cmath>

#include <Eigen/Geometry>
#include <opencv2/core.hpp>

#include <gtest/gtest.h>

#include "core/geometry.h"
#include "sim/sim_options.h"
#include "sim/simulator.h"

namespace everytouch::sim {
namespace {

SimParameters knockedRig(double knockS) {
    SimParameters parameters;
    parameters.scenario = "idle";
    parameters.knockS = knockS;
    // A small camera: what is tested is where it looks from, not what its pixels resolve.
    parameters.cameraSize = {164, 124};
    parameters.pixelSamples = 1;
    return parameters;
}

Eigen::Vector3d centreOf(const Eigen::Isometry3d& tableToDevice) {
    return -(tableToDevice.linear().transpose() * tableToDevice.translation());
}

// The same frame rendered by a rig that moved and by one that did not, both with the first rig's code: their
// mean difference, DN per pixel.
class FrameComparison {
public:
    FrameComparison(const SimParameters& moved, const SimParameters& still)
        : pattern_(rigPattern(moved)), moved_(moved, pattern_), still_(still, pattern_) {}

    double operator()(std::uint64_t index) {
        moved_.render(index, frame_, truth_);
        still_.render(index, reference_, truth_);
        return cv::norm(frame_.image, reference_.image, cv::NORM_L1) /
               static_cast<double>(frame_.image.total());
    }

private:
    cv::Mat pattern_;
    Simulator moved_, still_;
    core::Frame frame_, reference_;
    FrameTruth truth_;
};

TEST(SimKnock, TurnsAndShiftsTheCameraByTheSpecsAmountsAndLeavesTheCalibration) {
    SimParameters parameters = knockedRig(1.0);
    parameters.knockDeg = 0.8;
    parameters.knockMm = 3.0;
    const Simulator simulator(parameters, rigPattern(parameters));
    const core::Calibration before = simulator.geometryAt(0.99);
    const core::Calibration after = simulator.geometryAt(1.0);
    EXPECT_TRUE(before.tableToCamera.isApprox(simulator.calibration().tableToCamera));
    const double turnedDeg =
        Eigen::AngleAxisd(after.tableToCamera.linear() * before.tableToCamera.linear().transpose()).angle() *
        180.0 / M_PI;
    EXPECT_NEAR(turnedDeg, 0.8, 1e-9);
    EXPECT_NEAR((centreOf(after.tableToCamera) - centreOf(before.tableToCamera)).norm(), 3.0, 1e-9);
    EXPECT_TRUE(after.tableToProjector.isApprox(before.tableToProjector));
    EXPECT_TRUE(after.cameraMatrix.isApprox(before.cameraMatrix));
}

TEST(SimKnock, TheSameSeedKnocksTheSameWayAnotherSeedAnother) {
    SimParameters parameters = knockedRig(0.0);
    // The knock does not depend on the code: one pattern serves all three.
    const cv::Mat pattern = rigPattern(parameters);
    const Simulator first(parameters, pattern), again(parameters, pattern);
    EXPECT_TRUE(first.geometryAt(0.0).tableToCamera.isApprox(again.geometryAt(0.0).tableToCamera));
    parameters.seed = 2;
    const Simulator other(parameters, pattern);
    EXPECT_FALSE(other.geometryAt(0.0).tableToCamera.isApprox(first.geometryAt(0.0).tableToCamera, 1e-6));
}

TEST(SimKnock, FramesAfterTheKnockShowTheTableFromWhereTheCameraNowIs) {
    const SimParameters parameters = knockedRig(0.05);
    SimParameters still = parameters;
    still.knockS.reset();
    // Frames 0 and 2 come before the knock, 8 after it (120 frames/s), each compared with the same frame of
    // the rig that was not knocked; frame 0 again after frame 8 is the frame before the knock again.
    FrameComparison differs(parameters, still);
    EXPECT_EQ(differs(0), 0.0);
    EXPECT_EQ(differs(2), 0.0);
    EXPECT_GT(differs(8), 1.0);  // mean DN per pixel: the table's print and light in other places
    EXPECT_EQ(differs(0), 0.0);
}

TEST(SimDrift, TheProjectorsImageCreepsAtTheSpecsRateWhileTheCalibrationStays) {
    SimParameters parameters = knockedRig(1.0);
    parameters.knockS.reset();
    parameters.driftPxPerMin = 6.0;
    const Simulator simulator(parameters, rigPattern(parameters));
    const core::Calibration& calibration = simulator.calibration();
    EXPECT_TRUE(simulator.geometryAt(0.0).projectorMatrix.isApprox(calibration.projectorMatrix));
    // 6 px a minute: 1 px after 10 s, 2 px after 20 s, in one direction, to within its steps.
    const auto crept = [&](double seconds) {
        const core::Calibration now = simulator.geometryAt(seconds);
        EXPECT_TRUE(now.tableToCamera.isApprox(calibration.tableToCamera));
        EXPECT_TRUE(now.tableToProjector.isApprox(calibration.tableToProjector));
        return Eigen::Vector2d(now.projectorMatrix(0, 2) - calibration.projectorMatrix(0, 2),
                               now.projectorMatrix(1, 2) - calibration.projectorMatrix(1, 2));
    };
    const Eigen::Vector2d after10 = crept(10.0), after20 = crept(20.0);
    EXPECT_NEAR(after10.norm(), 1.0, 0.02);
    EXPECT_NEAR(after20.norm(), 2.0, 0.02);
    EXPECT_NEAR(after10.normalized().dot(after20.normalized()), 1.0, 1e-9);
    // The truth follows the image: the display pixel over a table point moves with it.
    const Eigen::Vector2d onTable(150.0, 100.0);
    const double movedPx =
        (core::applyHomography(simulator.geometryAt(20.0).displayToTableHomography().inverse(), onTable) -
         core::applyHomography(calibration.displayToTableHomography().inverse(), onTable))
            .norm();
    EXPECT_GT(movedPx, 1.0);
}

TEST(SimDrift, FramesShowTheCodeWhereTheImageHasCrept) {
    SimParameters parameters = knockedRig(1.0);
    parameters.knockS.reset();
    parameters.driftPxPerMin = 60.0;  // 1 px a second
    SimParameters still = parameters;
    still.driftPxPerMin = 0.0;
    FrameComparison differs(parameters, still);
    EXPECT_EQ(differs(0), 0.0);
    EXPECT_GT(differs(240), 1.0);  // 2 s: the code and the content 2 px away
    EXPECT_EQ(differs(0), 0.0);    // and the first frame again as it was
}

TEST(SimTableShift, TheTableSlidesAndTurnsInItsPlaneAndTheCodeStaysWhereTheCalibrationPutsIt) {
    SimParameters parameters = knockedRig(1.0);
    parameters.knockS.reset();
    parameters.tableShiftS = 1.0;
    parameters.tableShiftMm = 5.0;
    parameters.tableShiftDeg = 1.0;
    const Simulator simulator(parameters, rigPattern(parameters));
    const core::Calibration& calibration = simulator.calibration();
    const core::Calibration before = simulator.geometryAt(0.99), after = simulator.geometryAt(1.0);
    EXPECT_TRUE(before.tableToCamera.isApprox(calibration.tableToCamera));
    // The rig stands against the table as if the table had moved 5 mm and turned 1 degree about the vertical
    // through the display's centre: that centre moved by the slide alone.
    const Eigen::Isometry3d relative = before.tableToCamera.inverse() * after.tableToCamera;
    EXPECT_NEAR(Eigen::AngleAxisd(relative.linear()).angle() * 180.0 / M_PI, 1.0, 1e-9);
    EXPECT_NEAR(std::abs(Eigen::AngleAxisd(relative.linear()).axis().z()), 1.0, 1e-9);
    const Eigen::Vector2d centre = calibration.displayCentreOnTable();
    const Eigen::Vector3d centre3(centre.x(), centre.y(), 0.0);
    EXPECT_NEAR((relative * centre3 - centre3).norm(), 5.0, 1e-9);
    EXPECT_NEAR((relative * centre3 - centre3).z(), 0.0, 1e-9);
    EXPECT_TRUE((before.tableToProjector.inverse() * after.tableToProjector).isApprox(relative));
    // The table's plane is where it was: the code falls where the calibration predicts it.
    EXPECT_TRUE(after.projectorToCameraHomography().normalized().isApprox(
        calibration.projectorToCameraHomography().normalized(), 1e-9));
}

TEST(SimTableShift, FramesAfterTheSlideShowTheTablesPrintMovedAndTheCodeInPlace) {
    SimParameters parameters = knockedRig(1.0);
    parameters.knockS.reset();
    parameters.surface = SurfaceKind::Artifacts;  // print and stains that move with the table
    parameters.tableShiftS = 0.05;
    SimParameters still = parameters;
    still.tableShiftS.reset();
    FrameComparison differs(parameters, still);
    EXPECT_EQ(differs(2), 0.0);
    EXPECT_GT(differs(8), 0.5);  // mean DN per pixel: the print in other places
    EXPECT_EQ(differs(2), 0.0);
}

TEST(SimTableTilt, TheTableTiltsAboutALevelAxisThroughTheDisplaysCentreAndTheCodeMoves) {
    SimParameters parameters = knockedRig(1.0);
    parameters.knockS.reset();
    parameters.tableTiltS = 1.0;
    parameters.tableTiltDeg = 2.0;
    const Simulator simulator(parameters, rigPattern(parameters));
    const core::Calibration& calibration = simulator.calibration();
    const core::Calibration before = simulator.geometryAt(0.99), after = simulator.geometryAt(1.0);
    EXPECT_TRUE(before.tableToCamera.isApprox(calibration.tableToCamera));
    // The rig stands against the table as if the table had turned 2 degrees about a level axis through the
    // display's centre, which stays where it was; both devices keep their places against each other.
    const Eigen::Isometry3d relative = before.tableToCamera.inverse() * after.tableToCamera;
    const Eigen::AngleAxisd turn(relative.linear());
    EXPECT_NEAR(turn.angle() * 180.0 / M_PI, 2.0, 1e-9);
    EXPECT_NEAR(turn.axis().z(), 0.0, 1e-9);
    const Eigen::Vector2d centre = calibration.displayCentreOnTable();
    const Eigen::Vector3d centre3(centre.x(), centre.y(), 0.0);
    EXPECT_NEAR((relative * centre3 - centre3).norm(), 0.0, 1e-9);
    EXPECT_TRUE((before.tableToProjector.inverse() * after.tableToProjector).isApprox(relative));
    // Another plane: the code falls elsewhere than the calibration predicts.
    EXPECT_FALSE(after.projectorToCameraHomography().normalized().isApprox(
        calibration.projectorToCameraHomography().normalized(), 1e-4));
}

TEST(SimKnock, SpecKeysAreReadAndChecked) {
    SimParameters p;
    EXPECT_EQ(applyOption(p, "knock", "12.5"), std::nullopt);
    EXPECT_EQ(applyOption(p, "knock_deg", "1"), std::nullopt);
    EXPECT_EQ(applyOption(p, "knock_mm", "0"), std::nullopt);
    EXPECT_EQ(p.knockS, 12.5);
    EXPECT_EQ(p.knockDeg, 1.0);
    EXPECT_EQ(p.knockMm, 0.0);
    EXPECT_EQ(p.validate(), std::nullopt);
    p.knockS = -1.0;
    EXPECT_NE(p.validate().value_or("").find("knock:"), std::string::npos);
    p = SimParameters();
    p.knockDeg = 45.0;
    EXPECT_NE(p.validate().value_or("").find("knock_deg"), std::string::npos);
    p = SimParameters();
    p.knockMm = -2.0;
    EXPECT_NE(p.validate().value_or("").find("knock_mm"), std::string::npos);
    p = SimParameters();
    EXPECT_EQ(applyOption(p, "drift_px_per_min", "2"), std::nullopt);
    EXPECT_EQ(p.driftPxPerMin, 2.0);
    p.driftPxPerMin = 61.0;
    EXPECT_NE(p.validate().value_or("").find("drift_px_per_min"), std::string::npos);
    p = SimParameters();
    EXPECT_EQ(applyOption(p, "table_shift", "3"), std::nullopt);
    EXPECT_EQ(applyOption(p, "table_shift_mm", "8"), std::nullopt);
    EXPECT_EQ(applyOption(p, "table_shift_deg", "0.5"), std::nullopt);
    EXPECT_EQ(p.tableShiftS, 3.0);
    EXPECT_EQ(p.tableShiftMm, 8.0);
    EXPECT_EQ(p.tableShiftDeg, 0.5);
    EXPECT_EQ(p.validate(), std::nullopt);
    p.tableShiftMm = -1.0;
    EXPECT_NE(p.validate().value_or("").find("table_shift_mm"), std::string::npos);
    p = SimParameters();
    p.tableShiftDeg = 20.0;
    EXPECT_NE(p.validate().value_or("").find("table_shift_deg"), std::string::npos);
    p = SimParameters();
    EXPECT_EQ(applyOption(p, "table_tilt", "2"), std::nullopt);
    EXPECT_EQ(applyOption(p, "table_tilt_deg", "3"), std::nullopt);
    EXPECT_EQ(p.tableTiltS, 2.0);
    EXPECT_EQ(p.tableTiltDeg, 3.0);
    EXPECT_EQ(p.validate(), std::nullopt);
    p.tableTiltDeg = 11.0;
    EXPECT_NE(p.validate().value_or("").find("table_tilt_deg"), std::string::npos);
    p = SimParameters();
    p.tableTiltS = -1.0;
    EXPECT_NE(p.validate().value_or("").find("table_tilt:"), std::string::npos);
}

}  // namespace
}  // namespace everytouch::sim
