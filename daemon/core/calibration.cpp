#include "core/calibration.h"

#include <cmath>

#include "core/geometry.h"

namespace everytouch::core {

namespace {

bool allFinite(const auto& matrix) {
    return matrix.allFinite();
}

std::optional<std::string> checkSize(const cv::Size& size, const char* field) {
    if (size.width <= 0 || size.height <= 0)
        return std::string(field) + ": width and height must be positive";
    return std::nullopt;
}

std::optional<std::string> checkIntrinsics(const Eigen::Matrix3d& k, const char* field) {
    if (!allFinite(k))
        return std::string(field) + ": not all elements are finite";
    if (!(k(0, 0) > 0.0) || !(k(1, 1) > 0.0))
        return std::string(field) + ": focal lengths fx, fy must be positive";
    if (k(1, 0) != 0.0 || k(2, 0) != 0.0 || k(2, 1) != 0.0 || k(2, 2) != 1.0)
        return std::string(field) + ": must be upper triangular with a 1 in the bottom-right corner";
    return std::nullopt;
}

std::optional<std::string> checkRigid(const Eigen::Isometry3d& pose, const char* field) {
    const Eigen::Matrix4d& m = pose.matrix();
    if (!allFinite(m))
        return std::string(field) + ": not all elements are finite";
    if (m.row(3) != Eigen::RowVector4d(0, 0, 0, 1))
        return std::string(field) + ": the last row must be 0 0 0 1";
    const Eigen::Matrix3d r = pose.rotation();
    constexpr double kTolerance = 1e-6;
    if (!(r.transpose() * r).isApprox(Eigen::Matrix3d::Identity(), kTolerance) ||
        std::abs(r.determinant() - 1.0) > kTolerance)
        return std::string(field) + ": the upper-left 3x3 block is not a rotation";
    return std::nullopt;
}

}  // namespace

std::optional<std::string> Calibration::validate() const {
    if (auto problem = checkSize(cameraSize, "camera_size"))
        return problem;
    if (auto problem = checkIntrinsics(cameraMatrix, "camera_matrix"))
        return problem;
    if (!allFinite(cameraDistortion))
        return "camera_distortion: not all elements are finite";
    if (auto problem = checkSize(projectorSize, "projector_size"))
        return problem;
    if (auto problem = checkIntrinsics(projectorMatrix, "projector_matrix"))
        return problem;
    if (auto problem = checkRigid(tableToCamera, "table_to_camera"))
        return problem;
    if (auto problem = checkRigid(tableToProjector, "table_to_projector"))
        return problem;
    if (tableToCamera.translation().z() <= 0.0)
        return "table_to_camera: the table origin must lie in front of the camera (t_z > 0)";
    if (tableToProjector.translation().z() <= 0.0)
        return "table_to_projector: the table origin must lie in front of the projector (t_z > 0)";
    if (auto problem = checkSize(displaySize, "display_size"))
        return problem;
    if (!allFinite(displayToProjector))
        return "display_to_projector: not all elements are finite";
    if (std::abs(displayToProjector.determinant()) < 1e-12)
        return "display_to_projector: the homography is singular";
    return std::nullopt;
}

Eigen::Matrix3d Calibration::tableToCameraHomography(double heightMm) const {
    return planeToImageHomography(cameraMatrix, tableToCamera, heightMm);
}

Eigen::Matrix3d Calibration::tableToProjectorHomography(double heightMm) const {
    return planeToImageHomography(projectorMatrix, tableToProjector, heightMm);
}

Eigen::Matrix3d Calibration::projectorToCameraHomography(double heightMm) const {
    return tableToCameraHomography(heightMm) * tableToProjectorHomography(heightMm).inverse();
}

Eigen::Matrix3d Calibration::cameraToProjectorHomography(double heightMm) const {
    return tableToProjectorHomography(heightMm) * tableToCameraHomography(heightMm).inverse();
}

Eigen::Matrix3d Calibration::cameraToDisplayHomography(double heightMm) const {
    return displayToProjector.inverse() * cameraToProjectorHomography(heightMm);
}

Eigen::Matrix3d Calibration::cameraToDisplayBelowHomography(double heightMm) const {
    // The plane z = heightMm shares the table frame's x and y: a point's coordinates on it are those of the
    // point below it.
    return displayToTableHomography().inverse() * tableToCameraHomography(heightMm).inverse();
}

Eigen::Matrix3d Calibration::displayToTableHomography() const {
    return tableToProjectorHomography().inverse() * displayToProjector;
}

Eigen::Vector2d Calibration::displayCentreOnTable() const {
    return applyHomography(displayToTableHomography(), {displaySize.width / 2.0, displaySize.height / 2.0});
}

cv::Size2d Calibration::displaySizeMm() const {
    const Eigen::Matrix3d h = displayToTableHomography();
    const double w = displaySize.width, hgt = displaySize.height;
    const Eigen::Vector2d topLeft = applyHomography(h, {0, 0}), topRight = applyHomography(h, {w, 0});
    const Eigen::Vector2d bottomLeft = applyHomography(h, {0, hgt}),
                          bottomRight = applyHomography(h, {w, hgt});
    return {((topRight - topLeft).norm() + (bottomRight - bottomLeft).norm()) / 2.0,
            ((bottomLeft - topLeft).norm() + (bottomRight - topRight).norm()) / 2.0};
}

}  // namespace everytouch::core
