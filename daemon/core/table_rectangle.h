#pragma once

#include <array>
#include <optional>
#include <string>

#include <Eigen/Core>
#include <opencv2/core/mat.hpp>

#include "core/camera_model.h"
#include "core/result.h"

namespace everytouch::core {

// A dark rectangle of known size lying on a light surface: the paper uses a credit card's magnetic stripe to
// find H_TC. Any dark rectangle of known size (a whole dark card, a sheet of black paper) works.
struct TableRectangleOptions {
    // Longer side first, mm. ISO/IEC 7811 stripe: 85.5 x 12.5 mm (it runs the card's full width).
    cv::Size2d sizeMm{85.5, 12.5};
    // Steepest view of the surface the rectangle is accepted at, degrees from the surface's normal.
    // Perspective shortens one direction by up to the cosine of this angle, so the side ratio in the image
    // may be that much smaller or larger than the true one.
    double maxViewAngleDeg = 55.0;
    // The rectangle must be at least this much darker than the surface around it, digital levels. A black
    // stripe on a light table under the projector's white is about 150 DN darker.
    double minContrastDn = 20.0;
    // Shortest side in the image, pixels: each edge needs a few pixels of dark and light beside it.
    double minSidePx = 6.0;

    std::optional<std::string> validate() const;
};

struct TableRectangleDetection {
    // The corners at table (0, 0), (w, 0), (w, h), (0, h) mm, in undistorted pixels of the camera model. The
    // table's x axis runs along the longer side towards increasing camera columns; y completes a right-handed
    // frame with z towards the camera.
    std::array<Eigen::Vector2d, 4> corners;
    // H_TC^-1: table millimetres -> undistorted camera pixels.
    Eigen::Matrix3d tableToCamera = Eigen::Matrix3d::Identity();
    double edgeRmsPx = 0.0;   // scatter of the sub-pixel edge points about the four fitted lines
    double contrastDn = 0.0;  // surround minus inside
    int candidates = 0;       // dark quadrilaterals of a possible shape seen; the one closest in shape wins
};

// Finds the rectangle in an 8-bit gray or BGR camera frame. Its edges are located to sub-pixel precision
// (level crossings across each edge, undistorted with `camera`, one line fitted per edge) and the corners are
// the lines' intersections. A default CameraModel reports raw pixels. Fails when no such rectangle is in
// view; throws std::invalid_argument when options.validate() fails.
Result<TableRectangleDetection> findTableRectangle(const cv::Mat& cameraImage,
                                                   const TableRectangleOptions& options,
                                                   const CameraModel& camera = {});

}  // namespace everytouch::core
