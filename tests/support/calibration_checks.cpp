#include "support/calibration_checks.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include <gtest/gtest.h>
#include <Eigen/Geometry>

#include "core/geometry.h"
#include "io/calibration_file.h"

namespace everytouch::test {

double worstCameraToProjectorPx(const core::Calibration& found, const core::Calibration& truth) {
    double worstPx = 0;
    for (double x = 40; x <= truth.projectorSize.width - 40; x += 40)
        for (double y = 40; y <= truth.projectorSize.height - 40; y += 40) {
            const Eigen::Vector2d camera = core::applyHomography(truth.projectorToCameraHomography(), {x, y});
            if (camera.x() < 0 || camera.y() < 0 || camera.x() > truth.cameraSize.width - 1 ||
                camera.y() > truth.cameraSize.height - 1)
                continue;
            worstPx = std::max(worstPx, (core::applyHomography(found.cameraToProjectorHomography(), camera) -
                                         Eigen::Vector2d(x, y))
                                            .norm());
        }
    return worstPx;
}

core::Calibration withTheTableMoved(const core::Calibration& truth) {
    core::Calibration moved = truth;
    const Eigen::Isometry3d shift(Eigen::Translation3d(12, -5, -40) *
                                  Eigen::AngleAxisd(5 * M_PI / 180, Eigen::Vector3d::UnitX()));
    moved.tableToCamera = truth.tableToCamera * shift;
    moved.tableToProjector = truth.tableToProjector * shift;
    return moved;
}

std::optional<double> reportedRmsPx(const std::string& toolOutput) {
    double rmsPx = 0;
    if (std::sscanf(toolOutput.c_str(), "Calibrated: RMS reprojection error %lf px.", &rmsPx) != 1)
        return std::nullopt;
    return rmsPx;
}

void expectTheTableFound(const ProcessResult& tool, const std::filesystem::path& saved,
                         const core::Calibration& moved, const core::Calibration& truth) {
    EXPECT_EQ(tool.exitCode, 0) << tool.out << tool.err;
    const std::optional<double> rmsPx = reportedRmsPx(tool.out);
    EXPECT_TRUE(rmsPx) << "no RMS error reported: " << tool.out;
    if (tool.exitCode != 0 || !rmsPx)
        return;
    EXPECT_LE(*rmsPx, 0.5);
    const double worstPx = worstCameraToProjectorPx(io::readCalibrationFile(saved), truth);
    const double storedWorstPx = worstCameraToProjectorPx(moved, truth);
    ::testing::Test::RecordProperty("rms_px", std::to_string(*rmsPx));
    ::testing::Test::RecordProperty("worst_camera_to_projector_px", std::to_string(worstPx));
    ::testing::Test::RecordProperty("stored_worst_camera_to_projector_px", std::to_string(storedWorstPx));
    EXPECT_LT(worstPx, 0.5);
    EXPECT_GT(storedWorstPx, 2.0) << "the stored calibration should have been off";
}

}  // namespace everytouch::test
