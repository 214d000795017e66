#pragma once

#include <array>
#include <optional>

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <opencv2/core/types.hpp>

#include "core/camera_model.h"
#include "core/plane_view.h"
#include "core/projector_camera_pair.h"

namespace everytouch::core {

// First estimates for the calibrations' least squares: closed-form, noise-tolerant, not optimal.

// The plane through the view's correspondences, each triangulated as the midpoint of the shortest segment
// between its camera ray and its projector ray; camera frame, mm, normal towards the camera. Nothing when
// fewer than three points lie in front of both devices or they are collinear.
std::optional<Eigen::Hyperplane<double, 3>> triangulatePlane(const ProjectorCameraPair& pair,
                                                             const PlaneView& view);

// The rectangle's frame (origin at its (0, 0) corner, x along its longer side, z towards the camera) in the
// camera frame, from its corners' raw camera pixels cast onto `plane` and a rigid fit to its shape. Nothing
// when a corner's ray misses the plane or the corners' order gives z away from the camera.
std::optional<Eigen::Isometry3d> rectangleOnPlane(const CameraModel& camera,
                                                  const Eigen::Hyperplane<double, 3>& plane,
                                                  const std::array<Eigen::Vector2d, 4>& corners,
                                                  cv::Size2d rectangleSizeMm);

}  // namespace everytouch::core
