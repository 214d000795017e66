#pragma once

#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace everytouch::core {

// Standard deviation of a box one unit wide (a uniform distribution's): how a pixel's footprint blurs.
inline constexpr double kBoxSigmaPerWidth = 0.28867513459481287;  // 1 / sqrt(12)

// Homography from the plane z = heightMm of the table frame to a pinhole device's pixels (undistorted):
// K [r1, r2, heightMm * r3 + t] (paper eq. 19-21). `tableToDevice` maps table millimetres into the device
// frame.
Eigen::Matrix3d planeToImageHomography(const Eigen::Matrix3d& intrinsics,
                                       const Eigen::Isometry3d& tableToDevice, double heightMm);

// Paper eq. 22: from the table-induced homography H = K [r1, r2, t] (exact scale) and p3 = K r3, the map that
// takes the image of a table point (X, Y, 0) to the image of (X, Y, d): I + d [0, 0, p3] H^-1.
Eigen::Matrix3d elevatedPlaneHomography(const Eigen::Matrix3d& tableHomography, const Eigen::Vector3d& p3,
                                        double heightMm);

// Projects a point given in table millimetres into a pinhole device's pixels (undistorted).
Eigen::Vector2d projectPoint(const Eigen::Matrix3d& intrinsics, const Eigen::Isometry3d& tableToDevice,
                             const Eigen::Vector3d& pointInTable);

Eigen::Vector2d applyHomography(const Eigen::Matrix3d& homography, const Eigen::Vector2d& point);

// The homography taking `from` to `to` (at least four pairs, no three of the first four collinear): the
// normalised direct linear transform, exact for four pairs, algebraic least squares for more. Bottom-right
// element 1.
Eigen::Matrix3d fitHomography(const std::vector<Eigen::Vector2d>& from,
                              const std::vector<Eigen::Vector2d>& to);

// Rotation vector (axis times angle, radians; Rodrigues) <-> rotation matrix.
Eigen::Matrix3d rotationFromVector(const Eigen::Vector3d& rotationVector);
Eigen::Vector3d vectorFromRotation(const Eigen::Matrix3d& rotation);

}  // namespace everytouch::core
