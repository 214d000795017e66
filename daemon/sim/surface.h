#pragma once

#include <cstdint>

#include <Eigen/Core>
#include <opencv2/core/mat.hpp>

#include "sim/sim_parameters.h"

namespace everytouch::sim {

// Albedo of the table top: linear reflectance per channel (BGR, 0..1 stored as 0..255) on a regular grid of
// the table plane.
struct SurfaceTexture {
    cv::Mat albedo;                                              // CV_8UC3, linear reflectance x 255
    Eigen::Matrix3d tableToTexel = Eigen::Matrix3d::Identity();  // table mm -> texel coordinates
};

// A table top covering `areaMm` (x, y, width, height in table mm) at `mmPerTexel`: uniform gray or yellow
// with the faint unevenness of real furniture, or a light surface with artifacts (stains, rings, ink,
// sticky notes, print, scratches) like the paper's Fig. 15(d).
SurfaceTexture makeSurface(SurfaceKind kind, const cv::Rect2d& areaMm, double mmPerTexel, std::uint64_t seed);

}  // namespace everytouch::sim
