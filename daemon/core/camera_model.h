#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace everytouch::core {

// A pinhole camera with OpenCV's lens distortion (k1 k2 p1 p2 k3). "Raw" pixels are where the camera's sensor
// sees a point; "undistorted" pixels are where an ideal pinhole camera with the same matrix would see it. The
// pipeline works in undistorted pixels (Calibration); detectors find features in raw pixels.
struct CameraModel {
    Eigen::Matrix3d matrix = Eigen::Matrix3d::Identity();                          // K
    Eigen::Matrix<double, 5, 1> distortion = Eigen::Matrix<double, 5, 1>::Zero();  // k1 k2 p1 p2 k3

    // Point in the camera frame (z > 0) -> raw pixel.
    Eigen::Vector2d project(const Eigen::Vector3d& pointInCamera) const;
    // Normalised undistorted image coordinates (x/z, y/z) -> raw pixel.
    Eigen::Vector2d distortNormalised(const Eigen::Vector2d& normalised) const;
    // Raw pixel -> normalised undistorted image coordinates, i.e. the viewing ray (x, y, 1).
    Eigen::Vector2d undistortToNormalised(const Eigen::Vector2d& rawPixel) const;
    // Raw pixel -> undistorted pixel.
    Eigen::Vector2d undistortPixel(const Eigen::Vector2d& rawPixel) const;
    // Undistorted pixel -> raw pixel.
    Eigen::Vector2d distortPixel(const Eigen::Vector2d& undistortedPixel) const;
};

}  // namespace everytouch::core
