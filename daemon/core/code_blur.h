#pragma once

#include <optional>

#include <opencv2/core/mat.hpp>

#include "core/calibration.h"

namespace everytouch::core {

// How sharply this rig shows its code, measured on the table itself. The geometry says how wide a camera
// pixel's footprint on the panel is, but not how well the projector and the camera are focused: a projector
// a little out of focus (a Gaussian of 1.2 panel pixels) or a soft lens blurs the code on the table beyond
// what a prediction that assumes them sharp expects, and the table then looks like something else. The code
// is everywhere on the table, so its blur can be read from any pair: the prediction through the calibration,
// blurred by each candidate sigma, is correlated with S (both less their local means, so the content's
// brightness does not count), and the best candidate, refined between its neighbours, is the blur. A
// hand covering part of the table lowers the correlation for every candidate alike; it does not move the
// best.
class CodeBlurMeter {
public:
    // region: CV_8UC1, camera size, nonzero where the table's code is to be read (the judged display).
    void setRig(const Calibration& calibration, const cv::Mat& pattern, const cv::Mat& region);
    bool hasRig() const { return !sharp_.empty(); }

    // The camera's blur (Gaussian sigma, camera pixels) beyond a camera pixel's own footprint that makes the
    // table's predicted code follow S (CV_16SC1, camera size) best; nothing when S shows no code
    // significantly (a projector showing black, two frames of the same polarity), or shows it best beyond
    // kMostBlurPx, where the code is no longer readable.
    std::optional<double> measure(const cv::Mat& subtraction);

    // The candidates run from 0 to this in kStepPx steps.
    static constexpr double kMostBlurPx = 3.0;
    static constexpr double kStepPx = 0.25;
    // The best correlation must exceed this many standard deviations of chance.
    static constexpr double kSignificance = 5.0;

private:
    cv::Rect box_;      // the region's bounding box
    cv::Mat sharp_;     // CV_32FC1, box size: the table's code with no blur but the pixel's footprint
    cv::Mat inRegion_;  // CV_8UC1, box size
    double chance_ = 1.0;
    // Scratch, sized once per rig.
    cv::Mat subtraction_, localMean_, blurred_;
};

}  // namespace everytouch::core
