#include "core/projector_camera_pair.h"

namespace everytouch::core {

namespace {

// Point where the ray origin + s * direction (s > 0 or not) meets the plane.
Eigen::Vector3d intersect(const Eigen::Vector3d& origin, const Eigen::Vector3d& direction,
                          const Eigen::Hyperplane<double, 3>& plane) {
    const double s = -plane.signedDistance(origin) / plane.normal().dot(direction);
    return origin + s * direction;
}

}  // namespace

Eigen::Vector2d ProjectorCameraPair::cameraPixelOf(const Eigen::Vector2d& projectorPixel,
                                                   const Eigen::Hyperplane<double, 3>& plane) const {
    const Eigen::Matrix3d rotation = cameraToProjector.rotation();
    const Eigen::Vector3d projectorCentre = -(rotation.transpose() * cameraToProjector.translation());
    const Eigen::Vector3d direction =
        rotation.transpose() * projectorMatrix.inverse() * projectorPixel.homogeneous();
    return camera.project(intersect(projectorCentre, direction, plane));
}

Eigen::Vector2d ProjectorCameraPair::projectorPixelOf(const Eigen::Vector2d& rawCameraPixel,
                                                      const Eigen::Hyperplane<double, 3>& plane) const {
    const Eigen::Vector3d point = cameraToProjector * planePointOfCameraPixel(rawCameraPixel, plane);
    return (projectorMatrix * point).hnormalized();
}

Eigen::Vector3d ProjectorCameraPair::planePointOfCameraPixel(
    const Eigen::Vector2d& rawCameraPixel, const Eigen::Hyperplane<double, 3>& plane) const {
    return intersect(Eigen::Vector3d::Zero(), camera.undistortToNormalised(rawCameraPixel).homogeneous(),
                     plane);
}

Calibration ProjectorCameraPair::withTable(const Eigen::Isometry3d& tableToCamera) const {
    Calibration calibration;
    calibration.cameraSize = cameraSize;
    calibration.cameraMatrix = camera.matrix;
    calibration.cameraDistortion = camera.distortion;
    calibration.projectorSize = projectorSize;
    calibration.projectorMatrix = projectorMatrix;
    calibration.tableToCamera = tableToCamera;
    calibration.tableToProjector = cameraToProjector * tableToCamera;
    return calibration;
}

ProjectorCameraPair pairOf(const Calibration& calibration) {
    ProjectorCameraPair pair;
    pair.cameraSize = calibration.cameraSize;
    pair.camera = {calibration.cameraMatrix, calibration.cameraDistortion};
    pair.projectorSize = calibration.projectorSize;
    pair.projectorMatrix = calibration.projectorMatrix;
    pair.cameraToProjector = calibration.tableToProjector * calibration.tableToCamera.inverse();
    return pair;
}

}  // namespace everytouch::core
