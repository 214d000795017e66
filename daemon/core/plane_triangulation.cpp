#include "core/plane_triangulation.h"

#include <cmath>
#include <vector>

#include <Eigen/SVD>

namespace everytouch::core {

std::optional<Eigen::Hyperplane<double, 3>> triangulatePlane(const ProjectorCameraPair& pair,
                                                             const PlaneView& view) {
    const Eigen::Matrix3d rotation = pair.cameraToProjector.rotation();
    const Eigen::Vector3d projectorCentre = -(rotation.transpose() * pair.cameraToProjector.translation());
    const Eigen::Matrix3d projectorInverse = pair.projectorMatrix.inverse();
    std::vector<Eigen::Vector3d> points;
    for (size_t index = 0; index < view.cameraPoints.size(); ++index) {
        const Eigen::Vector3d cameraRay =
            pair.camera.undistortToNormalised(view.cameraPoints[index]).homogeneous();
        const Eigen::Vector3d projectorRay =
            rotation.transpose() * projectorInverse * view.projectorPoints[index].homogeneous();
        // Closest points: s * cameraRay and projectorCentre + u * projectorRay.
        const double a = cameraRay.dot(cameraRay), b = cameraRay.dot(projectorRay),
                     c = projectorRay.dot(projectorRay);
        const double d = cameraRay.dot(projectorCentre), e = projectorRay.dot(projectorCentre);
        const double denominator = a * c - b * b;
        if (std::abs(denominator) < 1e-12 * a * c)
            continue;  // parallel rays
        const double s = (d * c - b * e) / denominator, u = (b * d - a * e) / denominator;
        if (s <= 0 || u <= 0)
            continue;
        points.push_back((s * cameraRay + projectorCentre + u * projectorRay) / 2.0);
    }
    if (points.size() < 3)
        return std::nullopt;
    Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
    for (const Eigen::Vector3d& point : points)
        centroid += point;
    centroid /= static_cast<double>(points.size());
    Eigen::MatrixXd centred(3, points.size());
    for (size_t index = 0; index < points.size(); ++index)
        centred.col(index) = points[index] - centroid;
    const Eigen::JacobiSVD<Eigen::MatrixXd> svd(centred, Eigen::ComputeFullU);
    if (svd.singularValues()(1) < 1e-6 * svd.singularValues()(0))
        return std::nullopt;
    Eigen::Vector3d normal = svd.matrixU().col(2);
    if (normal.dot(-centroid) < 0)
        normal = -normal;
    return Eigen::Hyperplane<double, 3>(normal, centroid);
}

std::optional<Eigen::Isometry3d> rectangleOnPlane(const CameraModel& camera,
                                                  const Eigen::Hyperplane<double, 3>& plane,
                                                  const std::array<Eigen::Vector2d, 4>& corners,
                                                  cv::Size2d rectangleSizeMm) {
    const double w = rectangleSizeMm.width, h = rectangleSizeMm.height;
    Eigen::Matrix<double, 3, 4> model, seen;
    model << 0, w, w, 0, 0, 0, h, h, 0, 0, 0, 0;
    for (int corner = 0; corner < 4; ++corner) {
        const Eigen::Vector3d ray = camera.undistortToNormalised(corners[corner]).homogeneous();
        const double depth = -plane.offset() / plane.normal().dot(ray);
        if (!(depth > 0))
            return std::nullopt;
        seen.col(corner) = depth * ray;
    }
    Eigen::Isometry3d pose;
    pose.matrix() = Eigen::umeyama(model, seen, false);
    if (pose.rotation().col(2).dot(plane.normal()) <= 0)
        return std::nullopt;
    return pose;
}

}  // namespace everytouch::core
