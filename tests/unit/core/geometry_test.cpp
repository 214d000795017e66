#include "core/geometry.h"

#include <gtest/gtest.h>

#include "support/test_rig.h"

namespace everytouch::core {
namespace {

TEST(Geometry, PlaneHomographyMatchesDirectProjectionAtEveryHeight) {
    const Calibration calibration = test::paperLikeCalibration();
    for (double height : {0.0, 3.0, 10.0, 40.0}) {
        const Eigen::Matrix3d h =
            planeToImageHomography(calibration.cameraMatrix, calibration.tableToCamera, height);
        for (const Eigen::Vector2d& xy :
             {Eigen::Vector2d(0, 0), Eigen::Vector2d(250, 180), Eigen::Vector2d(-40, 90)}) {
            const Eigen::Vector2d direct =
                projectPoint(calibration.cameraMatrix, calibration.tableToCamera, {xy.x(), xy.y(), height});
            EXPECT_LT((applyHomography(h, xy) - direct).norm(), 1e-9) << "height " << height;
        }
    }
}

// Paper eq. 22: the table homography and the third column of P = K [R | t] give the homography of an elevated
// plane.
TEST(Geometry, ElevatedPlaneHomographyOfEquation22AgreesWithDirectProjection) {
    const Calibration calibration = test::paperLikeCalibration();
    const Eigen::Matrix3d tableHomography =
        planeToImageHomography(calibration.cameraMatrix, calibration.tableToCamera, 0.0);
    const Eigen::Vector3d p3 = calibration.cameraMatrix * calibration.tableToCamera.rotation().col(2);
    for (double height : {1.0, 6.0, 25.0}) {
        const Eigen::Matrix3d lift = elevatedPlaneHomography(tableHomography, p3, height);
        for (const Eigen::Vector2d& xy : {Eigen::Vector2d(10, 20), Eigen::Vector2d(300, 200)}) {
            const Eigen::Vector2d onTable = applyHomography(tableHomography, xy);
            const Eigen::Vector2d direct =
                projectPoint(calibration.cameraMatrix, calibration.tableToCamera, {xy.x(), xy.y(), height});
            EXPECT_LT((applyHomography(lift, onTable) - direct).norm(), 1e-6);
        }
    }
}

TEST(Geometry, HomographyRoundTripIsIdentity) {
    const Calibration calibration = test::paperLikeCalibration();
    const Eigen::Vector2d camera(300.25, 211.5);
    const Eigen::Vector2d projector = applyHomography(calibration.cameraToProjectorHomography(4.0), camera);
    EXPECT_LT((applyHomography(calibration.projectorToCameraHomography(4.0), projector) - camera).norm(),
              1e-9);
}

}  // namespace
}  // namespace everytouch::core
