#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <opencv2/core/types.hpp>

#include "core/calibration.h"
#include "core/camera_model.h"

namespace everytouch::core {

// The rigidly mounted projector and camera, calibrated once: both intrinsics and the transform between them.
// The projector is modelled as an inverse pinhole camera without lens distortion. Planes are given in the
// camera frame, in millimetres.
struct ProjectorCameraPair {
    cv::Size cameraSize;                                                  // pixels
    CameraModel camera;                                                   // K_c and its lens distortion
    cv::Size projectorSize;                                               // pixels
    Eigen::Matrix3d projectorMatrix = Eigen::Matrix3d::Identity();        // K_p
    Eigen::Isometry3d cameraToProjector = Eigen::Isometry3d::Identity();  // x_proj = R x_cam + t, mm

    // Where the projector pixel lands on `plane` and where the camera sees that point (raw camera pixel).
    Eigen::Vector2d cameraPixelOf(const Eigen::Vector2d& projectorPixel,
                                  const Eigen::Hyperplane<double, 3>& plane) const;
    // The projector pixel that lights the point of `plane` the camera sees at `rawCameraPixel`.
    Eigen::Vector2d projectorPixelOf(const Eigen::Vector2d& rawCameraPixel,
                                     const Eigen::Hyperplane<double, 3>& plane) const;
    // The point of `plane` (camera frame, mm) seen at `rawCameraPixel`.
    Eigen::Vector3d planePointOfCameraPixel(const Eigen::Vector2d& rawCameraPixel,
                                            const Eigen::Hyperplane<double, 3>& plane) const;

    // The pair and a table pose make a full calibration (display fields left at their defaults).
    Calibration withTable(const Eigen::Isometry3d& tableToCamera) const;
};

// The pair inside a full calibration.
ProjectorCameraPair pairOf(const Calibration& calibration);

}  // namespace everytouch::core
