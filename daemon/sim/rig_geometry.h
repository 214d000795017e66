#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "core/calibration.h"
#include "sim/sim_parameters.h"

namespace everytouch::sim {

// Pose of a pinhole device at `position` whose ray through `aimPixel` hits `target`, with image rows running
// across the table's y axis and image columns along +x. Returns the table-to-device transform.
Eigen::Isometry3d aimDevice(const Eigen::Matrix3d& intrinsics, const Eigen::Vector2d& aimPixel,
                            const Eigen::Vector3d& position, const Eigen::Vector3d& target);

// The exact calibration of the simulated rig: intrinsics and poses from the parameters, no distortion, and
// the display mapped onto the panel (keystone-corrected when asked for).
core::Calibration rigCalibration(const SimParameters& parameters);

}  // namespace everytouch::sim
