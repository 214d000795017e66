#pragma once

#include <Eigen/Core>

namespace everytouch::core {

// The filter's settings, in the units of the values it filters (display pixels for contacts) and hertz.
struct OneEuroParameters {
    double minCutoffHz = 1.0;         // cutoff of the position low-pass at rest
    double beta = 0.0;                // cutoff rise per unit of speed above the jitter speed, Hz per unit/s
    double derivativeCutoffHz = 5.0;  // cutoff of the low-pass on the speed estimate
    double positionNoise = 0.0;       // one standard deviation of a resting value's noise, per axis, units
};

// The One Euro filter (Casiez, Roussel, Vogel, CHI 2012) on a 2-D position: a first-order low-pass whose
// cutoff rises with the speed, so a still point is smoothed hard and a moving one follows with little lag.
//
// Two departures from the paper, both for contacts on a table:
// - The speed is the length of the velocity vector, so the filter treats every direction of travel alike.
// - Only the speed above what position noise alone produces (jitterSpeed) raises the cutoff. At 120 Hz a
//   resting finger with 0.5 mm of jitter shows a speed of 10 to 60 mm/s. With the paper's rule no choice of
//   parameters both cuts that jitter threefold and follows a finger starting at 0.5 m/s to within 1 mm after
//   five frames: a beta large enough for the start lets the jitter's speed open the filter at rest.
class OneEuroFilter {
public:
    // The first value after construction or reset() passes unchanged. dtS: seconds since the previous value.
    const Eigen::Vector2d& filter(const Eigen::Vector2d& value, double dtS,
                                  const OneEuroParameters& parameters);

    void reset();

    bool started() const { return started_; }
    // The last output.
    const Eigen::Vector2d& value() const { return value_; }
    // The low-passed rate of change of the output, units per second; zero until the second value.
    const Eigen::Vector2d& velocity() const { return velocity_; }

    // The speed estimate that noise of `positionNoise` on a resting value stays below in 99 % of frames, at a
    // frame interval of dtS, units per second.
    static double jitterSpeed(double positionNoise, double dtS, double derivativeCutoffHz);

private:
    bool started_ = false;
    Eigen::Vector2d value_ = Eigen::Vector2d::Zero();
    Eigen::Vector2d velocity_ = Eigen::Vector2d::Zero();
};

}  // namespace everytouch::core
