#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <opencv2/core/mat.hpp>
#include <opencv2/core/types.hpp>

#include "core/calibration.h"
#include "core/result.h"

namespace everytouch::core {

struct KeystoneFit {
    Eigen::Matrix3d displayToProjector = Eigen::Matrix3d::Identity();  // H_dp
    Eigen::AlignedBox2d tableRectangleMm;  // where the display appears on the table, table axes
};

// Keystone correction (the paper's use of H_PT): the display is mapped onto the largest rectangle of its
// aspect ratio, with sides along the table's x and y axes, that fits inside the quadrilateral the projector
// lights on the table, so that it appears undistorted: right angles, square pixels. The display keeps the
// projector's orientation (its x axis is the table axis closest to the projector's x axis; never mirrored).
// Uses the projector's size, matrix and table pose from `calibration`. Fails when the lit area is not a
// convex quadrilateral on the table or either size is empty.
Result<KeystoneFit> fitDisplayToTable(const Calibration& calibration, cv::Size displaySize);

// How the display lands on the table through the calibration: its sides (mm) and the least and largest of its
// corners' angles (degrees; 90 everywhere for an upright rectangle). Where the desktop reaches the panel
// unwarped (the overlay), the projector's own keystone must square it, and this says how far it is.
struct DisplayShape {
    double topMm = 0.0, bottomMm = 0.0, leftMm = 0.0, rightMm = 0.0;
    double leastCornerDeg = 0.0, largestCornerDeg = 0.0;
};
DisplayShape displayShapeOnTable(const Calibration& calibration);

// A display image as the projector shows it: drawn through displayToProjector onto a panel of panelSize
// pixels (bilinear), black where the display does not reach.
cv::Mat drawThroughKeystone(const cv::Mat& displayImage, const Eigen::Matrix3d& displayToProjector,
                            cv::Size panelSize);

// What a projector output is given to draw the display through: throws std::invalid_argument for an empty
// display size or a displayToProjector that is not a finite, invertible homography with H(2,2) != 0.
void checkDisplayToProjector(cv::Size displaySize, const Eigen::Matrix3d& displayToProjector);

}  // namespace everytouch::core
