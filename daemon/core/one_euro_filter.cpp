#include "core/one_euro_filter.h"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace everytouch::core {

namespace {

// Weight of the new sample in a first-order low-pass of cutoff `cutoffHz` sampled every dtS seconds.
double smoothing(double cutoffHz, double dtS) {
    const double timeConstant = 1.0 / (2.0 * std::numbers::pi * cutoffHz);
    return 1.0 / (1.0 + timeConstant / dtS);
}

}  // namespace

double OneEuroFilter::jitterSpeed(double positionNoise, double dtS, double derivativeCutoffHz) {
    // A resting value's raw derivative has about positionNoise / dtS of noise per axis (the filtered value it
    // is taken against barely moves); the low-pass of weight a keeps sqrt(a / (2 - a)) of white noise; and
    // the length of a 2-D Gaussian vector of that deviation per axis exceeds sqrt(2 ln 100) of it in 1 % of
    // samples.
    const double a = smoothing(derivativeCutoffHz, dtS);
    return std::sqrt(2.0 * std::log(100.0)) * positionNoise / dtS * std::sqrt(a / (2.0 - a));
}

const Eigen::Vector2d& OneEuroFilter::filter(const Eigen::Vector2d& value, double dtS,
                                             const OneEuroParameters& parameters) {
    if (!started_) {
        started_ = true;
        value_ = value;
        velocity_.setZero();
        return value_;
    }
    const Eigen::Vector2d rawVelocity = (value - value_) / dtS;
    velocity_ += smoothing(parameters.derivativeCutoffHz, dtS) * (rawVelocity - velocity_);
    const double excessSpeed = std::max(
        0.0, velocity_.norm() - jitterSpeed(parameters.positionNoise, dtS, parameters.derivativeCutoffHz));
    const double cutoffHz = parameters.minCutoffHz + parameters.beta * excessSpeed;
    value_ += smoothing(cutoffHz, dtS) * (value - value_);
    return value_;
}

void OneEuroFilter::reset() {
    started_ = false;
    value_.setZero();
    velocity_.setZero();
}

}  // namespace everytouch::core
