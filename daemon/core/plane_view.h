#pragma once

#include <array>
#include <optional>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <opencv2/core/types.hpp>

#include "core/projector_camera_pair.h"

namespace everytouch::core {

// One pose of a flat surface in front of the projector-camera pair: camera <-> projector correspondences on
// it (the corners of a projected chessboard, or dense ones decoded from the embedded code) and, when it lies
// on this surface, the dark rectangle of known size.
struct PlaneView {
    std::vector<Eigen::Vector2d> cameraPoints;     // raw camera pixels
    std::vector<Eigen::Vector2d> projectorPoints;  // the projector pixels lighting them, same order
    // The rectangle's corners at its (0, 0), (w, 0), (w, h), (0, h) mm (TableRectangleDetection order), raw
    // camera pixels.
    std::optional<std::array<Eigen::Vector2d, 4>> rectangleCorners;
};

// Number of residuals planeViewResiduals writes for `view`.
int residualCount(const PlaneView& view);

// Reprojection errors of a view, pixels, for the pair and the surface's plane (camera frame, mm): per
// correspondence the projector pixel predicted from the camera pixel minus the observed one (x, y), then the
// camera pixel predicted from the projector pixel minus the observed one (x, y); then, when the view has a
// rectangle, its four corners predicted from rectangleToCamera minus the observed ones. rectangleToCamera
// puts the rectangle into `plane`; it is ignored for a view without rectangle.
void planeViewResiduals(const ProjectorCameraPair& pair, const Eigen::Hyperplane<double, 3>& plane,
                        const PlaneView& view, const Eigen::Isometry3d& rectangleToCamera,
                        cv::Size2d rectangleSizeMm, double* residuals);

// The plane z = 0 of a frame given by its transform into the camera frame.
Eigen::Hyperplane<double, 3> planeOf(const Eigen::Isometry3d& frameToCamera);

// Root mean square reprojection errors, pixels, over all the views' residuals laid out as planeViewResiduals
// writes them one view after the other.
struct ReprojectionRms {
    double all = 0.0;        // every residual point
    double camera = 0.0;     // camera side: correspondences and rectangle corners
    double projector = 0.0;  // projector side
};
ReprojectionRms reprojectionRms(const std::vector<PlaneView>& views, const Eigen::VectorXd& residuals);

}  // namespace everytouch::core
