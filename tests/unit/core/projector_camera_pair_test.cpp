#include "core/projector_camera_pair.h"

#include <gtest/gtest.h>

#include "core/geometry.h"
#include "support/test_rig.h"

namespace everytouch::core {
namespace {

Eigen::Hyperplane<double, 3> tableInCamera(const Calibration& calibration) {
    const Eigen::Vector3d normal = calibration.tableToCamera.rotation().col(2);
    return Eigen::Hyperplane<double, 3>(normal, calibration.tableToCamera.translation());
}

TEST(ProjectorCameraPair, TransferThroughTheTableMatchesTheTableHomographies) {
    const Calibration calibration = test::paperLikeCalibration();
    const ProjectorCameraPair pair = pairOf(calibration);
    const Eigen::Hyperplane<double, 3> table = tableInCamera(calibration);
    for (const Eigen::Vector2d& projector :
         {Eigen::Vector2d(10, 20), Eigen::Vector2d(320, 240), Eigen::Vector2d(630, 470)}) {
        const Eigen::Vector2d camera = pair.cameraPixelOf(projector, table);
        EXPECT_LT((camera - applyHomography(calibration.projectorToCameraHomography(), projector)).norm(),
                  1e-9);
        EXPECT_LT((pair.projectorPixelOf(camera, table) - projector).norm(), 1e-9);
    }
}

TEST(ProjectorCameraPair, TransferFollowsLensDistortion) {
    Calibration calibration = test::paperLikeCalibration();
    calibration.cameraDistortion << -0.15, 0.1, 0, 0, 0;
    const ProjectorCameraPair pair = pairOf(calibration);
    const Eigen::Hyperplane<double, 3> table = tableInCamera(calibration);
    const Eigen::Vector3d point(40, 210, 0);
    const Eigen::Vector2d projector =
        projectPoint(calibration.projectorMatrix, calibration.tableToProjector, point);
    const Eigen::Vector2d raw = pair.camera.project(calibration.tableToCamera * point);
    EXPECT_LT((pair.cameraPixelOf(projector, table) - raw).norm(), 1e-9);
    EXPECT_LT((pair.projectorPixelOf(raw, table) - projector).norm(), 1e-9);
}

TEST(ProjectorCameraPair, WithTableGivesBackTheCalibration) {
    const Calibration calibration = test::paperLikeCalibration();
    const Calibration rebuilt = pairOf(calibration).withTable(calibration.tableToCamera);
    EXPECT_TRUE(rebuilt.tableToProjector.isApprox(calibration.tableToProjector, 1e-12));
    EXPECT_EQ(rebuilt.projectorMatrix, calibration.projectorMatrix);
}

}  // namespace
}  // namespace everytouch::core
