#include "core/edge_profile.h"

#include <algorithm>
#include <array>
#include <cmath>

namespace everytouch::core {

double sampleBilinear(const cv::Mat& gray, const Eigen::Vector2d& point) {
    const double x = std::clamp(point.x(), 0.0, gray.cols - 1.001);
    const double y = std::clamp(point.y(), 0.0, gray.rows - 1.001);
    const int x0 = static_cast<int>(x), y0 = static_cast<int>(y);
    const double fx = x - x0, fy = y - y0;
    const uchar* row0 = gray.ptr<uchar>(y0);
    const uchar* row1 = gray.ptr<uchar>(y0 + 1);
    return (1 - fy) * ((1 - fx) * row0[x0] + fx * row0[x0 + 1]) +
           fy * ((1 - fx) * row1[x0] + fx * row1[x0 + 1]);
}

std::optional<EdgeCrossing> locateEdgeCrossing(const cv::Mat& gray, const Eigen::Vector2d& base,
                                               const Eigen::Vector2d& direction, double reachPx,
                                               double minStepDn) {
    constexpr double kStepPx = 0.25;
    constexpr int kMaxSamples = 121;
    std::array<double, kMaxSamples> profile;
    const int samples = std::min(kMaxSamples, static_cast<int>(2.0 * reachPx / kStepPx) + 1);
    const double start = -(samples - 1) * kStepPx / 2.0;
    for (int sample = 0; sample < samples; ++sample)
        profile[sample] = sampleBilinear(gray, base + direction * (start + sample * kStepPx));
    // Each end's level from its first eighth.
    const int endSamples = std::max(2, samples / 8);
    double first = 0, last = 0;
    for (int sample = 0; sample < endSamples; ++sample) {
        first += profile[sample];
        last += profile[samples - 1 - sample];
    }
    first /= endSamples;
    last /= endSamples;
    const double step = last - first;
    if (!(std::abs(step) >= minStepDn))
        return std::nullopt;
    double area = 0.0;  // trapezoid rule over the profile's distance from its far level
    for (int sample = 0; sample + 1 < samples; ++sample)
        area += (2.0 * last - profile[sample] - profile[sample + 1]) / 2.0 * kStepPx;
    const double offset = start + area / step;
    if (std::abs(offset) > -start)
        return std::nullopt;
    return EdgeCrossing{offset, step};
}

}  // namespace everytouch::core
