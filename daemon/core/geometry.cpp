#include "core/geometry.h"

#include <cmath>

#include <Eigen/SVD>

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

Eigen::Matrix3d rotationFromVector(const Eigen::Vector3d& rotationVector) {
    const double angle = rotationVector.norm();
    if (angle < 1e-12) {
        Eigen::Matrix3d skew;
        skew << 0, -rotationVector.z(), rotationVector.y(), rotationVector.z(), 0, -rotationVector.x(),
            -rotationVector.y(), rotationVector.x(), 0;
        return Eigen::Matrix3d::Identity() + skew;
    }
    return Eigen::AngleAxisd(angle, rotationVector / angle).toRotationMatrix();
}

Eigen::Vector3d vectorFromRotation(const Eigen::Matrix3d& rotation) {
    const Eigen::AngleAxisd angleAxis(rotation);
    return angleAxis.angle() * angleAxis.axis();
}

namespace {

// Hartley's conditioning: moves the centroid to the origin and scales the mean distance to sqrt(2).
Eigen::Matrix3d conditioning(const std::vector<Eigen::Vector2d>& points) {
    Eigen::Vector2d mean = Eigen::Vector2d::Zero();
    for (const Eigen::Vector2d& point : points)
        mean += point;
    mean /= static_cast<double>(points.size());
    double spread = 0.0;
    for (const Eigen::Vector2d& point : points)
        spread += (point - mean).norm();
    spread /= static_cast<double>(points.size());
    const double scale = spread > 0 ? std::sqrt(2.0) / spread : 1.0;
    Eigen::Matrix3d transform;
    transform << scale, 0, -scale * mean.x(), 0, scale, -scale * mean.y(), 0, 0, 1;
    return transform;
}

}  // namespace

Eigen::Matrix3d fitHomography(const std::vector<Eigen::Vector2d>& from,
                              const std::vector<Eigen::Vector2d>& to) {
    const Eigen::Matrix3d fromConditioning = conditioning(from), toConditioning = conditioning(to);
    Eigen::MatrixXd system(2 * from.size(), 9);
    for (size_t index = 0; index < from.size(); ++index) {
        const Eigen::Vector3d a = fromConditioning * from[index].homogeneous();
        const Eigen::Vector2d b = applyHomography(toConditioning, to[index]);
        system.row(2 * index) << a.transpose(), 0, 0, 0, -b.x() * a.transpose();
        system.row(2 * index + 1) << 0, 0, 0, a.transpose(), -b.y() * a.transpose();
    }
    const Eigen::JacobiSVD<Eigen::MatrixXd> svd(system, Eigen::ComputeFullV);
    const Eigen::Matrix<double, 9, 1> solution = svd.matrixV().col(8);
    const Eigen::Matrix3d conditioned =
        Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(solution.data());
    Eigen::Matrix3d homography = toConditioning.inverse() * conditioned * fromConditioning;
    return homography / homography(2, 2);
}

}  // namespace everytouch::core
