#pragma once

#include <optional>
#include <string>

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <opencv2/core/types.hpp>

namespace everytouch::core {

// The calibration model of the projector-camera-table rig (docs/architecture.md, "Geometry and calibration
// model"). Table frame: x, y on the table in millimetres, z up. Every homography the pipeline needs is
// derived from it; camera pixels are undistorted pixels throughout.
struct Calibration {
    cv::Size cameraSize;                                         // camera image, pixels
    Eigen::Matrix3d cameraMatrix = Eigen::Matrix3d::Identity();  // K_c
    Eigen::Matrix<double, 5, 1> cameraDistortion = Eigen::Matrix<double, 5, 1>::Zero();  // k1 k2 p1 p2 k3
    cv::Size projectorSize;                                              // projector panel, pixels
    Eigen::Matrix3d projectorMatrix = Eigen::Matrix3d::Identity();       // K_p
    Eigen::Isometry3d tableToCamera = Eigen::Isometry3d::Identity();     // x_cam = R_c X_T + t_c, mm
    Eigen::Isometry3d tableToProjector = Eigen::Isometry3d::Identity();  // x_proj = R_p X_T + t_p, mm
    cv::Size displaySize;                                                // the desktop's image, pixels
    Eigen::Matrix3d displayToProjector = Eigen::Matrix3d::Identity();    // H_dp, keystone

    // The first problem found, phrased with the field names of the calibration file; nothing when usable.
    std::optional<std::string> validate() const;

    // Plane z = heightMm of the table frame (mm) -> camera pixels. Its inverse at height 0 is the paper's
    // H_TC.
    Eigen::Matrix3d tableToCameraHomography(double heightMm = 0.0) const;
    // Plane z = heightMm of the table frame (mm) -> projector pixels. Its inverse at height 0 is the paper's
    // H_TP.
    Eigen::Matrix3d tableToProjectorHomography(double heightMm = 0.0) const;
    // Projector pixels -> camera pixels through the plane at heightMm: the paper's H_CP (height 0) and H_CPd.
    Eigen::Matrix3d projectorToCameraHomography(double heightMm = 0.0) const;
    // Camera pixels -> projector pixels through the plane at heightMm: the paper's H_PC.
    Eigen::Matrix3d cameraToProjectorHomography(double heightMm = 0.0) const;
    // Camera pixels -> display pixels through the plane at heightMm: the display pixel whose light falls on
    // the point at that height the camera pixel sees.
    Eigen::Matrix3d cameraToDisplayHomography(double heightMm = 0.0) const;
    // Camera pixels -> the display pixel straight below the point at heightMm the camera pixel sees: where a
    // fingertip there lands when it comes straight down. Above the table the projector's ray and the
    // vertical part by the height times the ray's slope (0.4 mm per mm on the default rig).
    Eigen::Matrix3d cameraToDisplayBelowHomography(double heightMm) const;
    // Display pixels -> table millimetres (where the desktop's pixels land on the table).
    Eigen::Matrix3d displayToTableHomography() const;
    // The table point, mm, on which the display's centre lands.
    Eigen::Vector2d displayCentreOnTable() const;

    // Physical size of the displayed image on the table, from its four corners (mean of opposite sides), mm.
    cv::Size2d displaySizeMm() const;
};

}  // namespace everytouch::core
