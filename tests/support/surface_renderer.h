#pragma once

#include <vector>

#include <Eigen/Core>
#include <opencv2/core/mat.hpp>

#include "core/calibration.h"

namespace everytouch::test {

// A dark rectangle lying on the surface (a credit card's magnetic stripe, say), in the surface's millimetres:
// it spans origin + a * (cos angle, sin angle) + b * (-sin angle, cos angle), a in [0, width], b in [0,
// height].
struct DarkRectangle {
    Eigen::Vector2d originMm = Eigen::Vector2d::Zero();
    cv::Size2d sizeMm{85.5, 12.5};
    double angleRad = 0.0;
    double albedo = 0.08;  // a black stripe reflects a few per cent
};

// A flat light surface (the table, or a tilted board) seen by the camera and lit by the projector. The
// surface is the plane z = 0 of the calibration's "table" frame, so a tilted board is a calibration whose
// table transforms are the board's.
struct SurfaceScene {
    core::Calibration rig;
    std::vector<DarkRectangle> rectangles;
    double surfaceAlbedo = 0.8;    // a light table
    double ambientDn = 25.0;       // camera level of a white surface lit by the room alone
    double projectorGainDn = 250;  // camera level a full-white projector pixel adds on a white surface
};

// The 8-bit gray camera frame of the scene while the projector shows `projectorImage` (8-bit gray, projector
// size), with the camera's lens distortion. Each camera pixel integrates supersampling x supersampling rays;
// projector pixels are sharp squares. Gaussian noise of noiseSigmaDn is added before quantisation.
cv::Mat renderSurface(const SurfaceScene& scene, const cv::Mat& projectorImage, double noiseSigmaDn = 0.0,
                      unsigned seed = 1, int supersampling = 4);

// The scene's surface moved by `surfaceToTable` (a board lifted and tilted above the table): the calibration
// whose table frame is the board's.
core::Calibration onSurface(const core::Calibration& rig, const Eigen::Isometry3d& surfaceToTable);

}  // namespace everytouch::test
