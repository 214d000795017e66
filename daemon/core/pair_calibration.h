#pragma once

#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <opencv2/core/types.hpp>

#include "core/plane_view.h"
#include "core/projector_camera_pair.h"
#include "core/result.h"

namespace everytouch::core {

struct PairCalibrationOptions {
    cv::Size cameraSize;                     // pixels
    cv::Size projectorSize;                  // pixels
    cv::Size2d rectangleSizeMm{85.5, 12.5};  // the dark rectangle, longer side first (card stripe)
    // Each device's pixels are square (fx = fy), as in nearly every camera and projector: the views determine
    // the aspect ratio worst of all parameters, so fixing it makes the rest more precise.
    bool squarePixels = true;
    // Views with more correspondences (dense ones from the embedded code) are thinned evenly to this many:
    // beyond a few hundred well-spread points a view adds time, not accuracy.
    int maxPointsPerView = 400;
    // The calibration fails above this RMS reprojection error, pixels.
    double maxRmsPx = 1.0;

    std::optional<std::string> validate() const;
};

// One standard deviation of the estimates, from the residuals' scatter and the Jacobian at the optimum.
struct PairUncertainty {
    Eigen::Vector4d camera = Eigen::Vector4d::Zero();         // fx fy cx cy, pixels
    Eigen::Vector2d distortion = Eigen::Vector2d::Zero();     // k1 k2
    Eigen::Vector4d projector = Eigen::Vector4d::Zero();      // fx fy cx cy, pixels
    double rotationDeg = 0.0;                                 // camera -> projector, about the worst axis
    Eigen::Vector3d translationMm = Eigen::Vector3d::Zero();  // camera -> projector
};

struct PairCalibration {
    ProjectorCameraPair pair;
    std::vector<Eigen::Hyperplane<double, 3>> planes;  // each view's surface, camera frame, mm
    ReprojectionRms rmsPx;
    PairUncertainty standardDeviation;
    int iterations = 0;
};

// The one-time calibration of the rigid projector-camera pair, the projector being an inverse camera: camera
// intrinsics with radial distortion (k1, k2), projector intrinsics, and the transform between them, from
// views of a flat surface in several poses (the table, a plain board at different tilts). Each view pairs
// camera and projector pixels on its surface; the surfaces' poses are unknown. Correspondences alone
// determine only a projective reconstruction (everything up to the camera matrix and the plane at infinity);
// the dark rectangle of known size supplies the metric information and the scale, and must lie on at least
// three differently tilted surfaces (docs/calibration.md has the figures). Starts from a closed-form estimate
// (principal point at the centre, focal length from the rectangles' homographies, the projector calibrated
// from the surfaces so found) and minimises the reprojection errors in both devices over all parameters and
// the surfaces' poses with Levenberg-Marquardt. Fails, naming the view, when the views cannot determine the
// pair, and when the RMS reprojection error exceeds options.maxRmsPx. Throws std::invalid_argument when
// options.validate() fails.
Result<PairCalibration> calibrateProjectorCameraPair(const std::vector<PlaneView>& views,
                                                     const PairCalibrationOptions& options);

}  // namespace everytouch::core
