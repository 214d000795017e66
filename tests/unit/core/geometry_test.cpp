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

// The paper's H_CPd = H_Cd H_CP H_Pd^-1, each lift from eq. 22 of its own device, is the homography through
// the plane at height d that the calibration gives directly.
TEST(Geometry, EquationTwentyTwoForBothDevicesComposesTheElevatedCameraProjectorMap) {
    const Calibration calibration = test::paperLikeCalibration();
    const Eigen::Matrix3d tableToCamera = calibration.tableToCameraHomography();
    const Eigen::Matrix3d tableToProjector = calibration.tableToProjectorHomography();
    const Eigen::Vector3d cameraP3 = calibration.cameraMatrix * calibration.tableToCamera.rotation().col(2);
    const Eigen::Vector3d projectorP3 =
        calibration.projectorMatrix * calibration.tableToProjector.rotation().col(2);
    for (double height : {2.0, 10.0, 40.0}) {
        const Eigen::Matrix3d composed =
            elevatedPlaneHomography(tableToCamera, cameraP3, height) *
            calibration.projectorToCameraHomography() *
            elevatedPlaneHomography(tableToProjector, projectorP3, height).inverse();
        for (const Eigen::Vector2d& projector :
             {Eigen::Vector2d(40, 30), Eigen::Vector2d(320, 240), Eigen::Vector2d(600, 450)})
            EXPECT_LT((applyHomography(composed, projector) -
                       applyHomography(calibration.projectorToCameraHomography(height), projector))
                          .norm(),
                      1e-6)
                << "height " << height;
    }
}

TEST(Geometry, HomographyRoundTripIsIdentity) {
    const Calibration calibration = test::paperLikeCalibration();
    const Eigen::Vector2d camera(300.25, 211.5);
    const Eigen::Vector2d projector = applyHomography(calibration.cameraToProjectorHomography(4.0), camera);
    EXPECT_LT((applyHomography(calibration.projectorToCameraHomography(4.0), projector) - camera).norm(),
              1e-9);
}

TEST(Geometry, FitHomographyIsExactForFourPointsAndAgreesWithMore) {
    const Calibration calibration = test::paperLikeCalibration();
    const Eigen::Matrix3d truth = calibration.tableToCameraHomography();
    std::vector<Eigen::Vector2d> table, image;
    for (const Eigen::Vector2d& point :
         {Eigen::Vector2d(0, 0), Eigen::Vector2d(85.5, 0), Eigen::Vector2d(85.5, 12.5),
          Eigen::Vector2d(0, 12.5), Eigen::Vector2d(40, 200), Eigen::Vector2d(300, 90)}) {
        table.push_back(point);
        image.push_back(applyHomography(truth, point));
    }
    const std::vector<Eigen::Vector2d> firstFour(table.begin(), table.begin() + 4),
        firstFourImage(image.begin(), image.begin() + 4);
    for (const Eigen::Matrix3d& fitted :
         {fitHomography(firstFour, firstFourImage), fitHomography(table, image)})
        for (const Eigen::Vector2d& point : {Eigen::Vector2d(150, 150), Eigen::Vector2d(-30, 260)})
            EXPECT_LT((applyHomography(fitted, point) - applyHomography(truth, point)).norm(), 1e-6);
}

TEST(Geometry, RotationVectorRoundTrips) {
    for (const Eigen::Vector3d& vector : {Eigen::Vector3d(0.1, -0.2, 0.3), Eigen::Vector3d(0, 0, 3.0),
                                          Eigen::Vector3d(1e-14, 0, 0), Eigen::Vector3d(0, 0, 0)}) {
        const Eigen::Matrix3d rotation = rotationFromVector(vector);
        EXPECT_TRUE((rotation.transpose() * rotation).isApprox(Eigen::Matrix3d::Identity(), 1e-12));
        EXPECT_LT((vectorFromRotation(rotation) - vector).norm(), 1e-12);
    }
    EXPECT_TRUE(
        rotationFromVector({0, 0, M_PI / 2})
            .isApprox(Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitZ()).toRotationMatrix(), 1e-12));
}

}  // namespace
}  // namespace everytouch::core
