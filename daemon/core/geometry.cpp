#include "core/geometry.h"

namespace everytouch::core {

Eigen::Matrix3d planeToImageHomography(const Eigen::Matrix3d& intrinsics,
                                       const Eigen::Isometry3d& tableToDevice, double heightMm) {
    const Eigen::Matrix3d rotation = tableToDevice.rotation();
    Eigen::Matrix3d columns;
    columns.col(0) = rotation.col(0);
    columns.col(1) = rotation.col(1);
    columns.col(2) = heightMm * rotation.col(2) + tableToDevice.translation();
    return intrinsics * columns;
}

Eigen::Matrix3d elevatedPlaneHomography(const Eigen::Matrix3d& tableHomography, const Eigen::Vector3d& p3,
                                        double heightMm) {
    Eigen::Matrix3d lift = Eigen::Matrix3d::Zero();
    lift.col(2) = heightMm * p3;
    return Eigen::Matrix3d::Identity() + lift * tableHomography.inverse();
}

Eigen::Vector2d projectPoint(const Eigen::Matrix3d& intrinsics, const Eigen::Isometry3d& tableToDevice,
                             const Eigen::Vector3d& pointInTable) {
    return (intrinsics * (tableToDevice * pointInTable)).hnormalized();
}

Eigen::Vector2d applyHomography(const Eigen::Matrix3d& homography, const Eigen::Vector2d& point) {
    return (homography * point.homogeneous()).hnormalized();
}

}  // namespace everytouch::core
