#pragma once

#include <cstdint>

#include <Eigen/Core>
#include <opencv2/core/mat.hpp>

#include "core/calibration.h"
#include "core/frame.h"

namespace everytouch::test {

// A camera capture of the projected code on a plane, rendered from known geometry for tests: the pattern is
// embedded into content (core::embedCode), each projector pixel is a uniformly lit square, the camera
// integrates the light over each of its pixels' footprint, the surface reflects it with its albedo together
// with ambient light, and the sensor adds Gaussian noise and quantises to 8 bits.
struct SyntheticScene {
    cv::Mat pattern;                    // projector size, CV_8UC1, 0/1
    cv::Mat content;                    // projector size, CV_8UC3: the image people should see
    int delta = 10;                     // code amplitude, projector DN
    Eigen::Matrix3d projectorToCamera;  // homography the surface induces, projector px -> camera px
    cv::Size cameraSize{648, 488};      // pixels
    cv::Mat albedo;                     // camera size, CV_32FC3: reflectance per channel, 0..1
    double gain = 0.75;                 // camera DN per projector DN on a white surface
    double ambientDn = 30;              // ambient light reflected by a white surface, DN
    double noiseSigmaDn = 1;            // sensor noise per frame, DN
    int supersampling = 3;              // samples per camera pixel side for the area integration
    bool grayCamera = false;            // CV_8UC1 frames (mean of the channels) instead of CV_8UC3
    std::uint64_t seed = 1;             // noise
};

// The default pattern, core::generatePattern({}), generated once per process.
const cv::Mat& defaultPattern();

// The two frames of one pair: positive shows O + P, negative O - P.
core::FramePair renderCapture(const SyntheticScene& scene);

// Content with the cases that matter for the code: black, white, saturated colours, gradients, fine texture.
cv::Mat testContent(cv::Size size, std::uint64_t seed = 1);

// Albedo of a light table with a smooth 0.55..0.9 variation, a yellowish patch and a dark stain (0.25).
cv::Mat testAlbedo(cv::Size size);

// The paper-like rig of test_rig.h with another camera lens (same sensor, 7.4 um pixels): a longer lens makes
// the camera resolve the projector's pixels (6 mm: about 0.6 camera px per projector px; 10 mm: 1.0).
core::Calibration paperLikeCalibrationWithLens(double focalLengthMm);

}  // namespace everytouch::test
