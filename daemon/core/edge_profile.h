#pragma once

#include <optional>

#include <Eigen/Core>
#include <opencv2/core/mat.hpp>

namespace everytouch::core {

// Level of an 8-bit gray image between pixel centres (bilinear), clamped to the image.
double sampleBilinear(const cv::Mat& gray, const Eigen::Vector2d& point);

struct EdgeCrossing {
    double offsetPx = 0.0;  // where the edge crosses the profile, along `direction` from `base`
    double stepDn = 0.0;    // level after the edge minus before it, along `direction`
};

// Sub-pixel position of a step edge crossing the profile base + s * direction, s in [-reachPx, reachPx]
// (direction of unit length, reachPx at most 15). The area between the profile and its far level, divided by
// the step, is the distance from the profile's start to the edge, whatever the blur: unbiased to a few
// hundredths of a pixel where a threshold crossing is off by a tenth. Nothing when the step is below
// minStepDn or the edge is outside the profile.
std::optional<EdgeCrossing> locateEdgeCrossing(const cv::Mat& gray, const Eigen::Vector2d& base,
                                               const Eigen::Vector2d& direction, double reachPx,
                                               double minStepDn);

}  // namespace everytouch::core
